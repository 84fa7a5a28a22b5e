"""Writes small OME-Zarr pyramids with zarr-python (an independent writer) for
tests/ome_zarr.rs. Every value follows a formula the Rust test computes on its own.

    python ome_zarr_make.py OUTDIR

Level k holds level 0 sampled at every 2^k-th voxel (index 2^k j), so the test needs
no averaging: value_k(j) = formula(2^k j).
"""
import sys
from pathlib import Path

import numcodecs
import numpy as np
import zarr
from zarr.codecs import GzipCodec, ZstdCodec


def grid(shape):
    z, y, x = np.meshgrid(*(np.arange(n) for n in shape), indexing="ij")
    return x, y, z


def levels(level0, n, spatial=3):
    out = [level0]
    for _ in range(1, n):
        idx = (slice(None),) * (level0.ndim - spatial) + (slice(None, None, 2),) * spatial
        out.append(out[-1][idx])
    return out


def multiscale(axes, scale0, translation0=None, n=3, spatial=3):
    datasets = []
    for k in range(n):
        f = [1.0] * (len(axes) - spatial) + [2.0**k] * spatial
        t = [{"type": "scale", "scale": [s * g for s, g in zip(scale0, f)]}]
        if translation0 is not None:
            t.append({"type": "translation", "translation": list(translation0)})
        datasets.append({"path": str(k), "coordinateTransformations": t})
    return {"axes": axes, "datasets": datasets, "name": "fixture"}


def space(name, unit=None):
    a = {"name": name, "type": "space"}
    if unit:
        a["unit"] = unit
    return a


def write(root, version, arrays, attrs, **kw):
    g = zarr.open_group(str(root), mode="w", zarr_format=version)
    for k, a in enumerate(arrays):
        g.create_array(str(k), data=a, **kw)
    g.attrs.update(attrs)


def main(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    zyx = [space("z", "micrometer"), space("y", "micrometer"), space("x", "micrometer")]

    # (a) Zarr v2, NGFF 0.4, uint16, gzip, "/" separator, micrometres.
    x, y, z = grid((20, 24, 28))
    a = ((x * 7 + y * 13 + z * 31) % 4096).astype(np.uint16)
    ms = multiscale(zyx, [2.0, 0.5, 0.5])
    ms["version"] = "0.4"
    write(out / "v2_uint16.ome.zarr", 2, levels(a, 3), {"multiscales": [ms]}, chunks=(8, 8, 8),
          compressors=numcodecs.GZip(level=5), chunk_key_encoding={"name": "v2", "separator": "/"})

    # (b) Zarr v2, NGFF 0.4, int16, blosc (lz4), "." separator, no units.
    x, y, z = grid((9, 10, 11))
    b = (x - 3 * y + 5 * z - 100).astype(np.int16)
    ms = multiscale([space("z"), space("y"), space("x")], [1.0, 1.0, 1.0], [5.0, 6.0, 7.0], n=2)
    ms["version"] = "0.4"
    write(out / "v2_int16_blosc.ome.zarr", 2, levels(b, 2), {"multiscales": [ms]}, chunks=(4, 4, 4),
          compressors=numcodecs.Blosc(cname="lz4", clevel=5, shuffle=numcodecs.Blosc.SHUFFLE))

    # (c) Zarr v3, NGFF 0.5, float32, two channels, sharded with zstd inner chunks.
    x, y, z = grid((16, 20, 24))
    c0 = (x * 0.5 - y * 0.25 + z).astype(np.float32)
    c = np.stack([c0, c0 + 1000.0])
    axes = [{"name": "c", "type": "channel"}] + zyx
    ms = multiscale(axes, [1.0, 3.0, 1.0, 1.0], n=2)
    write(out / "v3_float32_sharded.ome.zarr", 3, levels(c, 2), {"ome": {"version": "0.5", "multiscales": [ms]}},
          chunks=(1, 4, 4, 4), shards=(1, 8, 8, 8), compressors=ZstdCodec(level=3))

    # (d) Zarr v3, NGFF 0.5, uint8, gzip, millimetres and a translation.
    x, y, z = grid((12, 14, 16))
    d = ((x + 2 * y + 3 * z) % 256).astype(np.uint8)
    ms = multiscale([space("z", "millimeter"), space("y", "millimeter"), space("x", "millimeter")],
                    [1.5, 1.0, 0.75], [-10.0, 20.0, 30.0])
    write(out / "v3_uint8.ome.zarr", 3, levels(d, 3), {"ome": {"version": "0.5", "multiscales": [ms]}},
          chunks=(8, 8, 8), compressors=GzipCodec(level=5))
    # (e) Zarr v3, NGFF 0.5, float32 with a display window and one NaN voxel (z, y, x =
    # 1, 2, 3), one level.
    x, y, z = grid((4, 6, 8))
    e = (x + 10 * y + 100 * z).astype(np.float32)
    e[1, 2, 3] = np.nan
    ms = multiscale(zyx, [1.0, 1.0, 1.0], n=1)
    omero = {"channels": [{"window": {"min": -100.0, "max": 500.0, "start": 0.0, "end": 400.0}}]}
    write(out / "v3_float32_nan.ome.zarr", 3, [e], {"ome": {"version": "0.5", "multiscales": [ms], "omero": omero}},
          chunks=(2, 3, 4), compressors=ZstdCodec(level=3))
    # (f) A float32 NIfTI (nibabel) for `focal convert`: values that are not whole
    # numbers (written as float32, Focal's 16-bit codes of them), anisotropic voxels and
    # an origin away from 0.
    import nibabel
    x, y, z = np.meshgrid(np.arange(21), np.arange(17), np.arange(12), indexing="ij")
    f = (1000.0 * np.sin(0.3 * x) * np.cos(0.2 * y) + 37.25 * z - 0.5).astype(np.float32)
    affine = np.diag([0.7, 0.8, 1.2, 1.0])
    affine[:3, 3] = [-20.0, 15.0, 7.5]
    nibabel.save(nibabel.Nifti1Image(f, affine), str(out / "float32_source.nii.gz"))
    print(f"wrote 5 pyramids with zarr-python {zarr.__version__} and a float32 NIfTI into {out}")


if __name__ == "__main__":
    main(sys.argv[1])
