#!/usr/bin/env bash
# The scaling study of docs/SCALING.md (issue #19): time and peak memory of one W·x, one
# Algorithm 2, the default `coseg pair` (warm cache) and one `coseg segment` (warm cache) as
# vertices, features and shapes grow. Every point runs in its own process, single-threaded
# (RAYON_NUM_THREADS=1 / --threads 1), under `/usr/bin/time -f "%e %U %S %M"`; the 1-minute load
# average is recorded beside it. Generated inputs only (no data files).
#
#   scripts/scaling_study.sh [wx] [alg2] [pair] [segment]     # default: all four
#   OUT=/tmp/coseg-scaling PAIR_LEVELS="1 2 3 5 7 9" SEGMENT_COUNTS="2 5 10 20 50 100 200" \
#     scripts/scaling_study.sh pair
#
# Output: $OUT/{wx,alg2,pair,segment}.csv, plotted and fitted by scripts/scaling_plot.py.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-/tmp/coseg-scaling}
PAIR_LEVELS=${PAIR_LEVELS:-"1 2 3 5 7 9"}
SEGMENT_COUNTS=${SEGMENT_COUNTS:-"2 5 10 20 50 100 200"}
VERTEX_AXIS=${VERTEX_AXIS:-"1000 2000 5000 10000 20000 50000 100000 200000"}
FEATURE_AXIS=${FEATURE_AXIS:-"10 30 100 300 1000"}
sections=("$@")
[ ${#sections[@]} -eq 0 ] && sections=(wx alg2 pair segment)
mkdir -p "$OUT"

cargo build --release --locked --example scaling_study --bin coseg
study=target/release/examples/scaling_study
coseg=target/release/coseg
export RAYON_NUM_THREADS=1

load() { cut -d' ' -f1 /proc/loadavg; }

# Runs "$@" under /usr/bin/time; prints "load,wall_s,user_s,sys_s,max_rss_kb,<stdout>".
timed() {
  local l t
  l=$(load)
  t=$(mktemp)
  local o
  o=$(/usr/bin/time -f "%e,%U,%S,%M" -o "$t" "$@")
  echo "$l,$(cat "$t")${o:+,$o}"
  rm -f "$t"
}

# The generated shapes: 200 quadrupeds (seed 1, the shipped collections' seed).
shapes=$OUT/quadrupeds
if [ ! -f "$shapes/quadrupeds_199.obj" ] || [ ! -f "$shapes/quadrupeds_041.obj" ]; then
  $coseg generate quadrupeds -o "$shapes" --count 200 --threads 1 -q
fi

operator_axis() { # kind
  local kind=$1 csv=$OUT/$1.csv
  echo "load1,wall_s,user_s,sys_s,max_rss_kb,$($study header)" >"$csv"
  for v in $VERTEX_AXIS; do timed $study "$kind" "$v" 300 >>"$csv"; done
  for f in $FEATURE_AXIS; do timed $study "$kind" 10000 "$f" >>"$csv"; done
  cat "$csv"
}

for s in "${sections[@]}"; do
  case $s in
  wx | alg2) operator_axis "$s" ;;
  pair)
    # Two small quadrupeds (2,466 and 2,556 vertices), each triangle cut into n² (Phong
    # tessellation); the cache is filled by a first (cold) run, the second run is measured.
    csv=$OUT/pair.csv
    echo "load1,wall_s,user_s,sys_s,max_rss_kb,level,vertices_a,vertices_b,cold_wall_s,cold_max_rss_kb" >"$csv"
    for n in $PAIR_LEVELS; do
      d=$OUT/pair/n$n
      mkdir -p "$d"
      for i in 41 181; do
        [ -f "$d/q$i.obj" ] || $study refine "$shapes/quadrupeds_$(printf %03d "$i").obj" "$n" "$d/q$i.obj" >/dev/null
      done
      va=$(grep -c '^v ' "$d/q41.obj")
      vb=$(grep -c '^v ' "$d/q181.obj")
      cold=$(timed $coseg pair "$d/q41.obj" "$d/q181.obj" -o "$d/out" --cache "$d/cache" \
        --threads 1 --no-pictures -q)
      warm=$(timed $coseg pair "$d/q41.obj" "$d/q181.obj" -o "$d/out" --cache "$d/cache" \
        --threads 1 --no-pictures -q)
      echo "$warm,$n,$va,$vb,$(echo "$cold" | cut -d, -f2),$(echo "$cold" | cut -d, -f5)" >>"$csv"
      tail -1 "$csv"
      du -sh "$d/cache"
    done
    ;;
  segment)
    # The first N generated quadrupeds; one cache shared by every N (a shape's entry does not
    # depend on the collection). Each N runs twice: the first fills the cache with the shapes
    # not yet in it, the second (warm) is measured.
    csv=$OUT/segment.csv
    echo "load1,wall_s,user_s,sys_s,max_rss_kb,shapes,total_vertices" >"$csv"
    cache=$OUT/segment-cache
    all=$(ls "$shapes"/*.obj | sort | head -n "$(echo "$SEGMENT_COUNTS" | tr ' ' '\n' | sort -n | tail -1)")
    for n in $SEGMENT_COUNTS; do
      d=$OUT/segment/n$n
      rm -rf "$d/in"
      mkdir -p "$d/in"
      for f in $(echo "$all" | head -n "$n"); do ln -s "$f" "$d/in/"; done
      total=$(cat "$d"/in/*.obj | grep -c '^v ')
      $coseg segment "$d/in" -o "$d/out" --cache "$cache" --threads 1 --no-pictures -q
      echo "$(timed $coseg segment "$d/in" -o "$d/out" --cache "$cache" --threads 1 \
        --no-pictures -q),$n,$total" >>"$csv"
      tail -1 "$csv"
    done
    ;;
  *) echo "unknown section $s" >&2 && exit 2 ;;
  esac
done
