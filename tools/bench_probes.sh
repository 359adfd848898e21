#!/usr/bin/env bash
# Probe benchmark (docs/probes.md#cost): bevy's Cornell box and level-single-10 baked at defaults
# (probes.auto on) and with probes.auto: false, one after the other in one run: the probes' count,
# their stage's seconds (--timings), probes per second, their share of the bake and the whole
# bake's time against the bake without them. Writes bench/probes.csv. A few minutes on 2 cores.
# Not part of the tests.
#   usage: tools/bench_probes.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
mkdir -p bench/probes
[ -f bench/levels/level-single-10.glb ] || /usr/bin/python3 tools/make_levels.py bench/levels single:10 > /dev/null
printf "probes:\n  auto: false\n" > bench/probes/off.yaml
echo "level,probes,probe_seconds,probes_per_second,share,bake_seconds,bake_without_probes_seconds,added" > bench/probes.csv
for level in assets/scenes/cornell-box-bevy/CornellBox.glb bench/levels/level-single-10.glb; do
  name=$(basename "$level" .glb)
  build/lmbake bake "$level" -o bench/probes/out-$name --timings=bench/probes/$name-on.csv > bench/probes/$name-on.log 2>&1
  build/lmbake bake "$level" -c bench/probes/off.yaml -o bench/probes/out-$name-off --timings=bench/probes/$name-off.csv \
    > bench/probes/$name-off.log 2>&1
  count=$(grep -o '^probes: [0-9]* (' bench/probes/$name-on.log | grep -o '[0-9]*')
  on=$(awk -F, '$1=="whole bake"{print $2}' bench/probes/$name-on.csv)
  off=$(awk -F, '$1=="whole bake"{print $2}' bench/probes/$name-off.csv)
  p=$(awk -F, '$1=="probes"{print $2}' bench/probes/$name-on.csv)
  awk -v n="$name" -v c="$count" -v p="$p" -v on="$on" -v off="$off" \
    'BEGIN{printf "%s,%d,%.3f,%.0f,%.4f,%.2f,%.2f,%.4f\n", n, c, p, c/p, p/on, on, off, on/off-1}' >> bench/probes.csv
done
column -s, -t bench/probes.csv
