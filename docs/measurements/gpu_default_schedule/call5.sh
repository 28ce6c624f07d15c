#!/usr/bin/env bash
# The full method's training time alone on country 0 and port 0: new default against densifying
# until 3500, one pass each (run on the warm machine of call 3, build-gpu/ already there).
export CALL_START=$(date +%s); source scripts/gpu/lib.sh; export OMP_NUM_THREADS=2
for k in country_0 port_0; do ( c=$(scene_cache $k) && pl_cache "$c" > /dev/null ) & done; wait
echo "[$(( $(date +%s) - CALL_START )) s] scenes"
echo '{"densify_until": 3500}' > /tmp/d3500.json; B=build-gpu/bin/sadsplat
for k in country_0 port_0; do
  pl=$(pl_cache "$(scene_cache $k)")
  for v in new d3500; do
    [ $(( 420 - ($(date +%s) - CALL_START) )) -gt 40 ] || break 2
    f=(--drop full); [ $v = d3500 ] && f+=(--config /tmp/d3500.json)
    $B train "$pl" --device cuda --out /tmp/u_$k$v "${f[@]}" > /tmp/u.log 2>&1
    echo "full $k $v: $(tr '\r' '\n' < /tmp/u.log | grep -o 'trained in [0-9.]* s' | tail -1) $(tr '\r' '\n' < /tmp/u.log | grep -o 'gaussians [0-9]*' | tail -1)"
  done
done
