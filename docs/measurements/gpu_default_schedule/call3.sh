#!/usr/bin/env bash
# The real survey under the new defaults (densify until 2000 of 7000), two seeds, then the full
# method's training time alone, new defaults against densifying until 3500, alternating.
set -u
export CALL_START=$(date +%s)
source scripts/gpu/lib.sh
gpu_build || exit 1
echo "[$(( $(date +%s) - CALL_START )) s] built"
export OMP_NUM_THREADS=2
( c=$(scene_cache city_0) && pl_cache "$c" > /dev/null ) &
E=scripts/gpu/experiments.sh
R=$PWD/.deps/real
specs=(); lspecs=()
for s in 42 1; do
  specs+=("net1_s$s:--drop none --seed $s" "structure_s$s:--drop structure --seed $s")
  lspecs+=("net1_s$s:--drop none --seed $s" "full_s$s:--drop full --seed $s")
done
( bash $E scene $R/brighton_800.cache 4 430 "${specs[@]}" > /tmp/a.log 2>&1 ) &
sleep 1
bash $E scene $R/brighton_lab800_pl.cache 4 430 "${lspecs[@]}" > /tmp/b.log 2>&1
wait
echo "[$(( $(date +%s) - CALL_START )) s] survey done"
echo '{"densify_until": 3500}' > /tmp/d3500.json
pl=$(pl_cache "$(scene_cache city_0)")
B=build-gpu/bin/sadsplat
for pass in 1 2; do
  for v in new d3500; do
    [ $(( 585 - ($(date +%s) - CALL_START) )) -gt 45 ] || break 2
    flags=(--drop full); [ $v = d3500 ] && flags+=(--config /tmp/d3500.json)
    $B train "$pl" --device cuda --out /tmp/t_$v$pass "${flags[@]}" > /tmp/t_$v$pass.log 2>&1
    echo "full city_0 $v pass $pass: $(tr '\r' '\n' < /tmp/t_$v$pass.log | grep -o 'trained in [0-9.]* s.*' | tail -1)" | tee -a $OUT/timing.txt
  done
done
(cd "$OUT" && tar cf scenes_tgz.tar scene_*.tgz && rm -f scene_*.tgz)
rm -f "$OUT"/gpu_build*.log "$OUT"/gpu_configure*.log "$OUT"/synth_*.log "$OUT"/pseudo_labels_*.log; ls "$OUT"
echo "call at $(( $(date +%s) - CALL_START )) s"
