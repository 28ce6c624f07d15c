#!/usr/bin/env bash
# ON THE GPU MACHINE from the repository root: work longer than one call (e.g. two 30000-iteration
# trainings, ~7 min together plus a ~2 min build), started in one call and collected by the next
# while the machine is still held (it goes back ~30 s after a call ends: call again at once).
#
#   bash scripts/gpu/background.sh start NAME CMD...   start CMD in its own session (it outlives
#                                                      the call) with OUT=/tmp/sadsplat-bg/NAME,
#                                                      then wait as below
#   bash scripts/gpu/background.sh launch NAME CMD...  start CMD as above and return at once, so
#                                                      that the call can run other work beside it
#                                                      (collect it with wait, this call or the next)
#   bash scripts/gpu/background.sh wait NAME           wait until CMD ends or UNTIL_S (575) seconds
#                                                      after this call's start; copy what CMD put in
#                                                      its OUT (*.txt, *.tgz, *.json) and its log to
#                                                      $OUT; print "NAME: running" or "NAME: rc N"
# The call's start is lib.sh's CALL_START (set by an outer script, else when this one starts).
#
# CMD inherits CALL_START (the first call's start, lib.sh), so an experiments.sh deadline counts
# from it: e.g. deadline 1110 s for a start call and one wait call. Example:
#   bash scripts/gpu/background.sh start long env ITERATIONS=30000 bash scripts/gpu/experiments.sh \
#       scene city_0_pl 2 1110 'none_long:--drop none --schedule long' 'full_long:--drop full --schedule long'
#   # next call:
#   bash scripts/gpu/background.sh wait long
set -uo pipefail
source "$(dirname "$0")/lib.sh"
mode="${1:?usage: background.sh start|launch NAME CMD... | wait NAME}"
name="${2:?a name for the background work}"
shift 2
dir=/tmp/sadsplat-bg/$name

if [ "$mode" = start ] || [ "$mode" = launch ]; then
  [ $# -gt 0 ] || { echo "background.sh $mode $name: no command given" >&2; exit 1; }
  if [ -f "$dir/pid" ] && kill -0 "$(cat "$dir/pid")" 2>/dev/null; then
    echo "background.sh $mode $name: already running (pid $(cat "$dir/pid"))" >&2
    exit 1
  fi
  rm -rf "$dir" && mkdir -p "$dir/out"
  OUT="$dir/out" CALL_START="$CALL_START" setsid nohup bash -c '"$@"; echo $? > "'"$dir"'/rc"' \
    background "$@" > "$dir/log" 2>&1 < /dev/null &
  echo $! > "$dir/pid"
  echo "$name: started (pid $(cat "$dir/pid")), log $dir/log"
  [ "$mode" = launch ] && exit 0
elif [ "$mode" != wait ]; then
  echo "background.sh: expected start, launch or wait, got $mode" >&2
  exit 1
fi

[ -f "$dir/pid" ] || { echo "background.sh wait $name: nothing was started under that name" >&2; exit 1; }
until_s="${UNTIL_S:-575}"
while [ ! -f "$dir/rc" ] && kill -0 "$(cat "$dir/pid")" 2>/dev/null &&
  [ $(( $(date +%s) - CALL_START )) -lt "$until_s" ]; do
  sleep 5
done
cp "$dir"/out/*.txt "$dir"/out/*.tgz "$dir"/out/*.json "$OUT"/ 2>/dev/null
cp "$dir/log" "$OUT/background_$name.log" 2>/dev/null
if [ -f "$dir/rc" ]; then
  echo "$name: rc $(cat "$dir/rc")"
elif kill -0 "$(cat "$dir/pid")" 2>/dev/null; then
  echo "$name: running"
else
  echo "$name: ended without a status (killed?)"
fi
tail -5 "$dir/log"
