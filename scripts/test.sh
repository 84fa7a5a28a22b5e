#!/usr/bin/env bash
# Runs the whole test suite: unit, reader, reference-renderer, shader, CLI and GPU image
# tests and the benchmark smoke run, then renders every example scene headless on the GPU
# into out/examples/.
source "$(dirname "$0")/env.sh"
cargo test --all-targets "$@"
echo "rendering the example scenes into out/examples/"
cargo run --quiet --bin focal -- render examples/*.ron --out out/examples
