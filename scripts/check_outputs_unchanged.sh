#!/bin/bash
# Outputs-unchanged check (issue #15): run BIN on the four shipped collections into OUTDIR, each
# collection with its own cache; run it with two binaries and `diff -rq` the two OUTDIRs (caches
# included). summary.json records input paths, so use the same COLLECTIONS_DIR for both.
# usage: scripts/check_outputs_unchanged.sh BIN OUTDIR [COLLECTIONS_DIR]
set -e
BIN=$1; OUT=$2; COLS=${3:-$(cd "$(dirname "$0")/.." && pwd)/collections}
mkdir -p "$OUT"
for c in chairs goblets humanoids quadrupeds; do
  d=$COLS/$c
  t0=$(date +%s.%N)
  $BIN segment "$d" -o "$OUT/$c-seg" --cache "$OUT/cache-$c" -q
  t1=$(date +%s.%N)
  $BIN segment "$d" --parts auto -o "$OUT/$c-auto" --cache "$OUT/cache-$c" -q
  t2=$(date +%s.%N)
  $BIN pair "$d/${c}_00.obj" "$d/${c}_01.obj" -o "$OUT/$c-pair" --cache "$OUT/cache-$c" -q
  t3=$(date +%s.%N)
  $BIN propagate "$d" --labels "$d/${c}_00.labels.txt" -o "$OUT/$c-prop" --cache "$OUT/cache-$c" -q
  t4=$(date +%s.%N)
  echo "$c segment $(echo "$t1-$t0"|bc) auto $(echo "$t2-$t1"|bc) pair $(echo "$t3-$t2"|bc) propagate $(echo "$t4-$t3"|bc)"
done
