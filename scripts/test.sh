#!/usr/bin/env bash
# Runs the whole test suite: unit, reader, reference-renderer and benchmark smoke tests.
source "$(dirname "$0")/env.sh"
cargo test --all-targets "$@"
