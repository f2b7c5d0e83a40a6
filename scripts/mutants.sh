#!/usr/bin/env bash
# Mutation testing with cargo-mutants (https://mutants.rs): injects small bugs into the named
# source files and reports those the test suite does not catch ("missed"). Settings live in
# .cargo/mutants.toml; results go to target/mutants/mutants.out (caught.txt, missed.txt, …).
#
#   scripts/mutants.sh [FILE…] [-- CARGO-MUTANTS-ARGS…]
#       mutate FILEs (default: the files whose logic decides results, listed below)
#   scripts/mutants.sh --diff [BASE] [-- CARGO-MUTANTS-ARGS…]
#       mutate only the lines changed since BASE (default: main), for a change under review
#
# Each mutant rebuilds the mutated crate and runs its package's tests: tens of seconds each on
# two cores, so run it in the background and use `--shard k/n` to split a long run. It is not
# part of CI. Install the tool once with `cargo install cargo-mutants --locked`.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo-mutants >/dev/null; then
    echo "cargo-mutants is not installed: cargo install cargo-mutants --locked" >&2
    exit 2
fi

# Incremental builds make each mutant a partial rebuild of one crate.
export CARGO_PROFILE_RELEASE_INCREMENTAL=true
out=target/mutants
mkdir -p "$out"

if [[ "${1:-}" == "--diff" ]]; then
    base="main"
    shift
    if [[ $# -gt 0 && "$1" != "--" ]]; then
        base="$1"
        shift
    fi
    [[ "${1:-}" == "--" ]] && shift
    diff_file="$out/change.diff"
    git diff "$base" -- '*.rs' >"$diff_file"
    exec cargo mutants --workspace --in-diff "$diff_file" -o "$out" "$@"
fi

files=()
while [[ $# -gt 0 && "$1" != "--" ]]; do
    files+=("$1")
    shift
done
[[ "${1:-}" == "--" ]] && shift
if [[ ${#files[@]} -eq 0 ]]; then
    files=(
        crates/balance/src/search.rs
        crates/balance/src/verify.rs
        crates/balance/src/enumerate.rs
        crates/dynamics/src/indicators.rs
        crates/vocabulary/src/indicators.rs
        crates/report/src/ranking.rs
        crates/optimise/src/critical/peaks.rs
        crates/optimise/src/critical/finish.rs
    )
fi
args=()
for f in "${files[@]}"; do
    args+=(-f "$f")
done
exec cargo mutants --workspace "${args[@]}" -o "$out" "$@"
