#!/usr/bin/env bash
# Runs every fuzz target in turn, SECONDS_EACH seconds each (default 300), niced, one at a time.
# cargo-fuzz needs nightly features; on a stable toolchain RUSTC_BOOTSTRAP=1 unlocks them.
#   cargo install cargo-fuzz --locked
#   fuzz/run.sh 300            # all targets, 5 minutes each
#   fuzz/run.sh 60 read_off    # one target
# Seeds: fuzz/seeds/<target> (committed); the growing corpus: fuzz/corpus/<target> (ignored);
# crashes: fuzz/artifacts/<target>/ (each needs a regression test, see docs/RELIABILITY.md).
set -euo pipefail
cd "$(dirname "$0")"
seconds=${1:-300}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(read_obj read_off read_ply read_ply_binary read_labels cache_entry)
fi
export RUSTC_BOOTSTRAP=1
nice -n 19 cargo fuzz build
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t"
    echo "== $t: ${seconds} s"
    nice -n 19 cargo fuzz run "$t" "corpus/$t" "seeds/$t" -- \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 2>&1 |
        tee "corpus/$t.log" | grep -E "^(stat::|==|SUMMARY|Done)" || true
done
