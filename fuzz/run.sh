#!/usr/bin/env bash
# Runs every fuzz target in turn, SECONDS_EACH seconds each (default 300), niced, one at a time.
# cargo-fuzz needs nightly features: the nightly toolchain when rustup has one, else the
# stable one with RUSTC_BOOTSTRAP=1 (which unlocks them).
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
    targets=(read_obj read_off read_ply read_ply_binary read_labels read_label_file cache_entry)
fi
if rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    cargo=(cargo +nightly)
else
    export RUSTC_BOOTSTRAP=1
    cargo=(cargo)
fi
nice -n 19 "${cargo[@]}" fuzz build
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t"
    echo "== $t: ${seconds} s"
    # The log keeps libFuzzer's status lines; the last "#N ... cov: ... ft: ..." line is the
    # coverage reached, stat::number_of_executed_units the executions.
    nice -n 19 "${cargo[@]}" fuzz run "$t" "corpus/$t" "seeds/$t" -- \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
        >"corpus/$t.log" 2>&1 || echo "$t: exit $? (a crash? see fuzz/artifacts/$t/)"
    grep -E "^#[0-9]+" "corpus/$t.log" | tail -n 1 || true
    grep -E "^(stat::|SUMMARY|==[0-9]+==ERROR|Done)" "corpus/$t.log" || true
done
