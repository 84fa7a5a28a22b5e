#!/usr/bin/env bash
# Runs the whole test suite: the format and lint gates (cargo fmt --check, cargo clippy
# with warnings as errors), unit, reader, reference-renderer, shader, layer, CLI, OME-Zarr
# (against zarr-python, nibabel and numpy: the oracle environment is set up here) and GPU
# image tests and the benchmark smoke run, then renders every example scene headless on
# the GPU, and slice views of ch2 and the AAL atlas, into out/examples/.
source "$(dirname "$0")/env.sh"
ensure_lint_tools
ensure_oracle
echo "checking the format (cargo fmt --check)"
cargo fmt --check
cargo test --all-targets "$@"
echo "linting (cargo clippy --all-targets -- -D warnings)"
cargo clippy --quiet --all-targets -- -D warnings
echo "converting ch2 to OME-Zarr for the example scenes (out/zarr/)"
cargo run --quiet --bin focal -- convert ../shared/data/mri/ch2.nii.gz out/zarr/ch2.ome.zarr --force
echo "rendering the example scenes into out/examples/"
cargo run --quiet --bin focal -- render examples/*.ron --out out/examples
echo "rendering slice views of ch2 and the AAL atlas into out/examples/"
for o in axial coronal sagittal; do
    cargo run --quiet --bin focal -- render ../shared/data/mri/ch2.nii.gz --slice "$o" --out "out/examples/slices-ch2-$o.png"
done
cargo run --quiet --bin focal -- render ../shared/data/labels/aal.nii.gz --labels --slice axial:100 --out out/examples/slices-aal-axial.png
