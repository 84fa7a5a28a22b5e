#!/usr/bin/env bash
# Runs Focal. Without arguments: the built-in head phantom; headless, it renders the
# default view to out/focal.png. Any arguments go to `focal` (try --help).
source "$(dirname "$0")/env.sh"
exec cargo run --quiet --bin focal -- "$@"
