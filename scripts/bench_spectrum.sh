#!/usr/bin/env bash
# coseg's spectrum against SciPy's eigsh on the same meshes and matrices: alternating runs,
# REPEATS rounds, the load average printed before every run, medians at the end.
# Usage: PYTHON=/path/to/venv/python scripts/bench_spectrum.sh REPEATS K MESH...
# SciPy must be installed as its users get it (pip wheels, bundled OpenBLAS) and run with no
# OPENBLAS_* / OMP_* overrides; scipy_spectrum.py prints what threadpoolctl reports.
set -u
reps=$1; k=$2; shift 2
py=${PYTHON:-python3}
env | grep -E '^(OPENBLAS|OMP|MKL)_' && { echo "unset the BLAS overrides above first"; exit 1; }
cargo build --release --example bench_spectrum >/dev/null 2>&1
log=$(mktemp)
for r in $(seq 1 "$reps"); do
  for mesh in "$@"; do
    echo "== round $r $mesh k $k load $(cut -d' ' -f1-3 /proc/loadavg)"
    ./target/release/examples/bench_spectrum -k "$k" --repeat 1 "$mesh" | tee -a "$log" | head -2
    echo "-- scipy, load $(cut -d' ' -f1-3 /proc/loadavg)"
    "$py" scripts/scipy_spectrum.py "$mesh" -k "$k" | tee -a "$log" | grep -E 'blas|eigsh'
  done
done
for mesh in "$@"; do
  c=$(grep -F "$mesh:" "$log" | grep -o 'median [0-9.]*' | awk '{print $2}' | sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}')
  s=$(grep -A2 -F "$mesh:" "$log" | grep -o 'eigsh [0-9.]*' | awk '{print $2}' | sort -g | awk '{a[NR]=$1} END{print a[int((NR+1)/2)]}')
  echo "$mesh k=$k: coseg median $c s, scipy median $s s, ratio $(echo "$c / $s" | bc -l | cut -c1-5)"
done
rm -f "$log"
