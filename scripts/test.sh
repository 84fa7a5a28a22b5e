#!/usr/bin/env bash
# Runs the whole test suite: the format and lint gates (cargo fmt --check, cargo clippy
# with warnings as errors), unit, reader, reference-renderer, shader, layer, CLI, OME-Zarr
# (against zarr-python, nibabel and numpy: the oracle environment is set up here) and GPU
# image tests and the benchmark smoke run, then renders every example scene headless on
# the GPU (their animations as movies), and slice views of ch2 and the AAL atlas, into
# out/examples/, and names the README gallery's real-data pictures in out/gallery/.
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
# The README gallery's real-data pictures, each named after its technique and dataset.
echo "naming the README gallery's real-data pictures in out/gallery/ (TECHNIQUE-DATASET.png)"
mkdir -p out/gallery
while read -r name frame; do
    cp "out/examples/$frame" "out/gallery/$name"
done <<'LIST'
lens-engine.png lens-engine.png
lens-ch2.png lens-ch2.png
context-ch2.png context_fig3_ch2-fig3_kt6_ks0_4.png
context-engine.png context_fig4_engine-fig4_context_preserving.png
twolevel-ch2_aal.png twolevel_ch2_aal-twolevel_dvr_mip_context.png
windows-ch2_aal.png windows_ch2-fig3_lens_with_other_contents.png
windows-ch2.png windows_ch2-fig4_source_box_elsewhere.png
explode-engine.png explode_fig5_viewing-viewing_on.png
explode-engine_slider.png explode_fig7_slider-degree_1.png
movie-lens-engine.gif movie_lens_engine/movie_lens_engine.gif
LIST
