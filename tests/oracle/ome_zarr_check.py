"""Checks a pyramid written by `focal convert` with independent tools: the source read by
nibabel, the pyramid read by zarr-python, every level recomputed with numpy.

    python ome_zarr_check.py SOURCE.nii[.gz] PYRAMID.ome.zarr [--labels]

Level k+1 of level k (z, y, x): an odd size rounds up, the last voxel standing in for
the missing one; intensities take floor((sum of the 2x2x2 block + 4) / 8), labels the
block's first voxel. A float32 pyramid (a source whose values are not whole numbers)
holds Focal's 16-bit codes of the values: level k is checked against the exact means of
the source's values, within (1/2 + k/2) code steps (the quantisation, then each level's
rounding of its mean code). Level 0's translation is the source's origin where its
axes are those of the world (else Focal writes none). Prints one JSON line; exits 1 on
the first difference.
"""
import json
import sys

import nibabel
import numpy as np
import zarr


def halve(a, labels, floats=False):
    if labels:
        return a[::2, ::2, ::2]
    pad = [(0, n % 2) for n in a.shape]
    p = np.pad(a if floats else a.astype(np.int64), pad, mode="edge")
    s = sum(p[dz::2, dy::2, dx::2] for dz in (0, 1) for dy in (0, 1) for dx in (0, 1))
    return s / 8.0 if floats else np.floor_divide(s + 4, 8)


def fail(msg):
    print(json.dumps({"ok": False, "error": msg}))
    sys.exit(1)


def main(src, pyramid, labels):
    img = nibabel.load(src)
    data = np.asarray(img.dataobj)
    if data.ndim > 3:
        data = data[..., 0]
    level = np.transpose(data, (2, 1, 0))  # x, y, z -> z, y, x
    zooms = np.array(img.header.get_zooms()[:3], dtype=float)[::-1]
    g = zarr.open_group(pyramid, mode="r")
    attrs = dict(g.attrs)
    if "ome" in attrs:
        version, ms = attrs["ome"]["version"], attrs["ome"]["multiscales"][0]
        zarr_format = 3
    else:
        ms = attrs["multiscales"][0]
        version, zarr_format = ms["version"], 2
    if g.metadata.zarr_format != zarr_format:
        fail(f"NGFF {version} in a Zarr v{g.metadata.zarr_format} group")
    if [a["name"] for a in ms["axes"]] != ["z", "y", "x"]:
        fail(f"axes {ms['axes']}")
    floats = np.issubdtype(g[ms["datasets"][0]["path"]].dtype, np.floating)
    if floats:
        level = level.astype(np.float64)
        step = (np.nanmax(level) - np.nanmin(level)) / 65535.0
    elif not np.issubdtype(level.dtype, np.integer):
        fail(f"an integer pyramid ({g[ms['datasets'][0]['path']].dtype}) of a {level.dtype} source")
    t0 = None
    for k, d in enumerate(ms["datasets"]):
        arr = g[d["path"]]
        got = arr[...]
        if got.shape != level.shape:
            fail(f"level {k}: shape {got.shape}, expected {level.shape}")
        if floats:
            tolerance = step * (0.5 + 0.5 * k) + 1e-6 * np.abs(level).max()
            err = np.abs(got.astype(np.float64) - level)
            if not err.max() <= tolerance:
                bad = tuple(np.argwhere(err == err.max())[0])
                fail(f"level {k}: value {got[bad]} at z,y,x {bad}, expected {level[bad]} within {tolerance}")
        elif not np.array_equal(got.astype(np.int64), level.astype(np.int64)):
            bad = np.argwhere(got.astype(np.int64) != level.astype(np.int64))[0]
            fail(f"level {k}: value {got[tuple(bad)]} at z,y,x {tuple(bad)}, expected {level[tuple(bad)]}")
        tr = {t["type"]: t for t in d["coordinateTransformations"]}
        scale = np.array(tr["scale"]["scale"])
        if not np.allclose(scale, zooms * 2**k, rtol=1e-5):
            fail(f"level {k}: scale {scale}, expected {zooms * 2**k}")
        t = np.array(tr["translation"]["translation"])
        if t0 is None:
            rotation = img.affine[:3, :3]
            if np.allclose(rotation, np.diag(np.diag(rotation))) and (np.diag(rotation) > 0).all():
                expected = img.affine[:3, 3][::-1]
                if not np.allclose(t, expected, atol=1e-4):
                    fail(f"level 0: translation {t}, expected the source's origin {expected} (z, y, x)")
            t0 = t
        if not np.allclose(t - t0, zooms * (2**k - 1) / 2, atol=1e-4):
            fail(f"level {k}: translation {t} moves {t - t0} from level 0, expected {zooms * (2**k - 1) / 2}")
        if k + 1 < len(ms["datasets"]):
            level = halve(level, labels, floats)
    print(json.dumps({"ok": True, "levels": len(ms["datasets"]), "version": version, "zarr_format": zarr_format,
                      "dtype": str(g[ms["datasets"][0]["path"]].dtype)}))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], "--labels" in sys.argv[3:])
