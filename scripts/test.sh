#!/usr/bin/env bash
# Runs the whole test suite: the format and lint gates (cargo fmt --check, cargo clippy
# with warnings as errors), unit, reader, reference-renderer, shader, layer, CLI and GPU
# image tests and the benchmark smoke run, then renders every example scene headless on
# the GPU into out/examples/.
source "$(dirname "$0")/env.sh"
ensure_lint_tools
echo "checking the format (cargo fmt --check)"
cargo fmt --check
cargo test --all-targets "$@"
echo "linting (cargo clippy --all-targets -- -D warnings)"
cargo clippy --quiet --all-targets -- -D warnings
echo "rendering the example scenes into out/examples/"
cargo run --quiet --bin focal -- render examples/*.ron --out out/examples
