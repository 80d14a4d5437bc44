#!/usr/bin/env bash
# Side-by-side timing of `coseg pair` with its defaults, warm: several coseg binaries run on the
# same pair in alternation, round after round, each with its own cache (filled by a first,
# untimed run) and output folder. Prints wall, user and system seconds and peak RSS per run.
#
#   scripts/bench_pair.sh ROUNDS A.off B.off BINARY [BINARY ...]
#   e.g. scripts/bench_pair.sh 3 $H/victoria0.off $H/david0.off /tmp/old/coseg target/release/coseg
#
# docs/PERFORMANCE.md ("Fifth pass") reports the medians of these runs.
set -euo pipefail
rounds=$1 a=$2 b=$3
shift 3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for i in $(seq $#); do
  bin=${!i}
  "$bin" -q pair "$a" "$b" -o "$work/out$i" --cache "$work/cache$i" >/dev/null 2>&1
done
for r in $(seq "$rounds"); do
  for i in $(seq $#); do
    bin=${!i}
    printf '%s round %d: ' "$bin" "$r"
    /usr/bin/time -f "%e s wall %U user %S sys %M KB" \
      "$bin" -q pair "$a" "$b" -o "$work/out$i" --cache "$work/cache$i" 2>&1 >/dev/null | tail -1
  done
done
