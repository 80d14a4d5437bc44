#!/usr/bin/env bash
# Back-to-back timing of coseg's spectrum and SciPy's eigsh on the same meshes, repeated.
# Usage: scripts/bench_spectrum.sh REPEATS MESH...   (prints load average before every run)
set -u
reps=$1; shift
cargo build --release --example bench_spectrum >/dev/null 2>&1
for r in $(seq 1 "$reps"); do
  for mesh in "$@"; do
    for k in 100 200; do
      echo "== round $r mesh $mesh k $k load $(cut -d' ' -f1-3 /proc/loadavg)"
      ./target/release/examples/bench_spectrum -k "$k" --repeat 1 "$mesh"
      echo "-- scipy load $(cut -d' ' -f1-3 /proc/loadavg)"
      python3 scripts/scipy_spectrum.py "$mesh" -k "$k"
    done
  done
done
