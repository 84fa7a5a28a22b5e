# Shared setup for the scripts: target directory outside the clone, one build profile,
# and the system packages Focal needs, installed when missing.
set -euo pipefail

export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/focal-target}"
export CARGO_TERM_COLOR="${CARGO_TERM_COLOR:-never}"

# Debian packages: software Vulkan (lavapipe) for GPU rendering where there is no GPU,
# a virtual X server for the app's window test, OpenSSL's headers for the HTTP store of
# OME-Zarr pyramids (reqwest's TLS), and cmake with a C++ compiler for CharLS (the
# JPEG-LS decoder of DICOM files).
FOCAL_PACKAGES=(mesa-vulkan-drivers xvfb xauth libssl-dev pkg-config cmake g++)

ensure_packages() {
  local missing=()
  for p in "${FOCAL_PACKAGES[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "installing: ${missing[*]}" >&2
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq >&2
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}" >&2
}

# rustfmt and clippy, the lint gates of scripts/test.sh (rustup's default profile has
# them; added when a minimal toolchain lacks them).
ensure_lint_tools() {
  if cargo fmt --version >/dev/null 2>&1 && cargo clippy --version >/dev/null 2>&1; then
    return 0
  fi
  echo "installing: rustfmt clippy (rustup component add)" >&2
  rustup component add rustfmt clippy >&2 || {
    echo "scripts/test.sh needs rustfmt and clippy: install them with 'rustup component add rustfmt clippy'" >&2
    return 1
  }
}

# The independent oracle of the OME-Zarr tests (tests/oracle/): zarr-python, numpy and
# nibabel in a virtual environment outside the clone, never a dependency of Focal.
FOCAL_ORACLE_VENV="${FOCAL_ORACLE_VENV:-$HOME/.cache/focal-oracle}"
ensure_oracle() {
  local py="$FOCAL_ORACLE_VENV/bin/python"
  if ! "$py" -c "import zarr, numpy, nibabel, numcodecs" >/dev/null 2>&1; then
    echo "installing the test oracle (zarr, numpy, nibabel) into $FOCAL_ORACLE_VENV" >&2
    if ! python3 -m venv "$FOCAL_ORACLE_VENV" >&2 2>&1; then
      # Debian's python3 without ensurepip: the venv module comes with python3-venv.
      FOCAL_PACKAGES=(python3-venv) ensure_packages
      python3 -m venv "$FOCAL_ORACLE_VENV" >&2
    fi
    "$py" -m pip install --quiet --disable-pip-version-check "zarr>=3.1,<4" numpy nibabel numcodecs >&2
  fi
  export FOCAL_ORACLE_PYTHON="$py"
}

cd "$(dirname "${BASH_SOURCE[0]}")/.."
ensure_packages

# wgpu: Vulkan (its GL backend panics on these machines).
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
# winit and Vulkan loaders want a private runtime directory.
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "${XDG_RUNTIME_DIR}" ]; then
  export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/focal-runtime-$(id -u)"
  mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
fi
