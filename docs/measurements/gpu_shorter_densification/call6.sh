#!/usr/bin/env bash
set -u
export CALL_START=$(date +%s)
source scripts/gpu/lib.sh
gpu_build || exit 1
echo '{"densify_until": 2000}' > /tmp/d2000.json
echo '{"opacity_reset_interval": 3600}' > /tmp/noreset.json
export OMP_NUM_THREADS=2
for k in city_0 port_0 country_0; do ( c=$(scene_cache $k) && pl_cache "$c" > /dev/null ) & done; wait
echo "[$(( $(date +%s) - CALL_START )) s] scenes made"
E=scripts/gpu/experiments.sh
( bash $E scene city_0 1 560 "net1_noreset:--drop none --config /tmp/noreset.json" > /tmp/a.log 2>&1 ) &
( bash $E scene port_0 1 560 "net1_noreset:--drop none --config /tmp/noreset.json" > /tmp/b.log 2>&1 ) &
( bash $E scene city_0_pl 1 560 "full_noreset:--drop full --config /tmp/noreset.json" > /tmp/c.log 2>&1 ) &
( bash $E scene country_0_pl 1 560 "full_d2000:--drop full --config /tmp/d2000.json" > /tmp/e.log 2>&1 ) &
bash $E scene port_0_pl 2 560 "full_noreset:--drop full --config /tmp/noreset.json" "full_d2000:--drop full --config /tmp/d2000.json"
wait
for f in /tmp/a.log /tmp/b.log /tmp/c.log /tmp/e.log; do grep -v "^$" $f | tail -4; done
(cd "$OUT" && tar cf scenes_tgz.tar scene_*.tgz && rm -f scene_*.tgz)
rm -f "$OUT"/gpu_*.log "$OUT"/synth_*.log "$OUT"/pseudo_labels_*.log; ls "$OUT"
echo "call at $(( $(date +%s) - CALL_START )) s"
