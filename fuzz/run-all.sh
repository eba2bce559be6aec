#!/usr/bin/env bash
# Runs every fuzz target for SECONDS each (default 20) on stable Rust:
# `cargo fuzz run -s none` (no sanitizer; the sanitizer builds need nightly
# flags). Installs cargo-fuzz if it is missing. Prints executions per
# second per target; exits non-zero at the first target that finds a
# crash (the input is left under fuzz/artifacts/TARGET/).
#
#   bash fuzz/run-all.sh [SECONDS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")"
seconds="${1:-20}"
shift || true

if ! cargo fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --locked
fi

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    mapfile -t targets < <(cargo fuzz list)
fi

# Build all targets once (release, debug assertions on, no sanitizer).
cargo fuzz build -s none

summary=()
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t"
    log="$(mktemp)"
    echo "== $t (${seconds} s)"
    if ! cargo fuzz run -s none "$t" "corpus/$t" -- \
        -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
        >"$log" 2>&1; then
        tail -40 "$log"
        echo "fuzz target $t FAILED; the input is in fuzz/artifacts/$t/"
        exit 1
    fi
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
    secs=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*' || echo 0)
    summary+=("$(printf '%-20s %10s runs %8s exec/s  coverage %s' "$t" "$runs" "$secs" "$cov")")
    rm -f "$log"
done
echo "== summary (${seconds} s per target)"
printf '%s\n' "${summary[@]}"
