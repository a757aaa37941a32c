"""Files (vsgl/io.h): multilayer EXR and scene bundles through the binding."""

import numpy as np
import pytest

import libvsgl as L
from conftest import require
from exr_read import read_exr
from scenes import floor_and_wall


def _exr(path):
    """Channels and attributes as OpenImageIO reads them (an independent reader)."""
    return read_exr(str(path))


def test_exr_write_passes(lib, ctx, tmp_path):
    require(lib, "vsgl_exr_write")
    H, W = 5, 7
    rgb = np.random.default_rng(1).random((H, W, 3), dtype=np.float32)
    a = np.ones((H, W), np.float32)
    path = tmp_path / "out.exr"
    L.exr_write(ctx, str(path), {"DiffInd": rgb, "Mask": a, "Combined": (np.dstack([rgb, a]), "RGBA")},
                metadata={"vsgl.test": "yes"})
    chans, attrs = _exr(path)
    for c in ("VSGL.DiffInd.R", "VSGL.DiffInd.G", "VSGL.DiffInd.B", "VSGL.Mask.V",
              "VSGL.Combined.A"):
        assert c in chans, sorted(chans)
    got = np.dstack([chans["VSGL.DiffInd." + c] for c in "RGB"])
    assert np.array_equal(got, rgb), "float pixels read back differ"     # float: exact
    assert np.array_equal(chans["VSGL.Mask.V"], a) and attrs.get("vsgl.test") == "yes", attrs
    with pytest.raises(ValueError):
        L.exr_write(ctx, str(path), {"A": rgb, "B": rgb[:2]})  # size mismatch
    with pytest.raises(TypeError):
        L.exr_write(ctx, str(path), {"A": rgb.astype(np.float64)})


def test_exr_write_zip_level(lib, ctx, tmp_path):
    """zip_level reaches the writer: lossless at 1 and 9 (OpenImageIO reads the same pixels), 9's file
    of a smooth image smaller, 0 the default level's bytes, 10 refused by name."""
    require(lib, "vsgl_exr_write")
    y, x = np.mgrid[0:64, 0:96].astype(np.float32)
    rgb = np.dstack([0.3 + 0.2 * np.sin(0.07 * x + c) * np.cos(0.05 * y) for c in range(3)]).astype(np.float32)
    paths = {}
    for level in (1, 9, 0, L.EXR_ZIP_LEVEL_DEFAULT):
        paths[level] = tmp_path / ("z%d.exr" % level)
        L.exr_write(ctx, str(paths[level]), {"DiffInd": rgb}, pixel_type="half", zip_level=level)
    a, b = _exr(paths[1])[0], _exr(paths[9])[0]
    assert all(np.array_equal(a[c], b[c]) for c in a), "zip levels 1 and 9 read back differently"
    assert paths[9].stat().st_size < paths[1].stat().st_size
    assert paths[0].read_bytes() == paths[L.EXR_ZIP_LEVEL_DEFAULT].read_bytes()
    with pytest.raises(L.VsglError) as e:
        L.exr_write(ctx, str(tmp_path / "z10.exr"), {"DiffInd": rgb}, zip_level=10)
    assert "EXR zip level 10 is not 1..9" in e.value.message, e.value.message


def test_exr_write_nan_is_refused_with_message(lib, ctx, tmp_path):
    require(lib, "vsgl_exr_write")
    rgb = np.zeros((4, 4, 3), np.float32)
    rgb[3, 2, 1] = np.nan
    path = tmp_path / "nan.exr"
    with pytest.raises(L.VsglError) as e:
        L.exr_write(ctx, str(path), {"DiffInd": rgb})
    assert e.value.code == L.Result.ERROR_INVALID_ARGUMENT
    assert "DiffInd" in e.value.message and "(2, 3)" in e.value.message, e.value.message
    assert not path.exists()


def test_exr_write_io_error_names_path(lib, ctx, tmp_path):
    require(lib, "vsgl_exr_write")
    bad = tmp_path / "no_such_dir" / "x.exr"
    with pytest.raises(L.VsglError) as e:
        L.exr_write(ctx, str(bad), {"DiffInd": np.zeros((2, 2, 3), np.float32)})
    assert e.value.code == L.Result.ERROR_IO and str(bad.parent) in e.value.message, e.value.message


def test_exr_write_render(lib, ctx, tmp_path):
    require(lib, "vsgl_exr_write_render", "vsgl_render", "vsgl_scene_create")
    scene = L.Scene(ctx, **floor_and_wall())
    images, _ = L.render(ctx, scene, L.render_settings_preset("preview"))
    path = tmp_path / "render.exr"
    L.exr_write_render(ctx, str(path), images)
    chans, _ = _exr(path)
    for p in ("DiffInd", "GlossInd", "DiffCol", "GlossCol", "Diff", "Gloss"):
        got = np.dstack([chans["VSGL.%s.%s" % (p, c)] for c in "RGB"])
        want = images[{v: k for k, v in L.PLANE_PASS_NAMES.items()}[p]]
        assert np.allclose(got, want, rtol=1e-3, atol=1e-6), p      # half or float
    assert np.allclose(chans["VSGL.Combined.A"], images["alpha"])


def test_check_output_path(lib, ctx, tmp_path):
    require(lib, "vsgl_check_output_path")
    L.check_output_path(ctx, str(tmp_path / "ok.exr"))
    assert not (tmp_path / "ok.exr").exists()
    with pytest.raises(L.VsglError) as e:
        L.check_output_path(ctx, str(tmp_path / "missing" / "x.exr"))
    assert e.value.code == L.Result.ERROR_IO
    with pytest.raises(L.VsglError):
        L.check_output_path(ctx, str(tmp_path))  # a directory


def _scene_with_everything():
    s = floor_and_wall()
    T = len(s["indices"])
    rng = np.random.default_rng(3)
    n = rng.normal(size=(T, 3, 3)).astype(np.float32)
    s["corner_normals"] = n / np.linalg.norm(n, axis=2, keepdims=True)
    s["corner_uvs"] = rng.random((T, 3, 2), dtype=np.float32)
    s["material_indices"] = np.zeros(T, np.uint32)
    return s


def _assert_same_scene(a, b):
    for k in ("positions", "indices", "corner_normals", "corner_uvs", "corner_tangents",
              "material_indices"):
        if a.get(k) is None:
            assert b[k] is None, k
        else:
            np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    assert [m.as_dict() for m in a["materials"]] == [m.as_dict() for m in b["materials"]]
    assert [x.as_dict() for x in a["lights"]] == [x.as_dict() for x in b["lights"]]
    assert a["camera"].as_dict() == b["camera"].as_dict()


def test_bundle_file_roundtrip(lib, ctx, tmp_path):
    require(lib, "vsgl_bundle_write", "vsgl_bundle_read", "vsgl_bundle_scene",
            "vsgl_bundle_settings", "vsgl_bundle_get_info", "vsgl_bundle_destroy")
    s = _scene_with_everything()
    settings = L.RenderSettings(aa_samples=2, fit_mode="fis", vsgl_count=16, seed=7)
    path = tmp_path / "scene.vsglb"
    L.bundle_write(ctx, str(path), s, settings, output_path="/tmp/out.exr", frame=12)
    scene, settings2, info = L.bundle_read(ctx, str(path))
    _assert_same_scene(s, scene)
    assert settings2.as_dict() == settings.as_dict()
    assert info["output_path"] == "/tmp/out.exr" and info["has_frame"] and info["frame"] == 12
    assert (info["version_major"], info["version_minor"]) == L.BUNDLE_VERSION
    # what was read builds a scene
    L.Scene(ctx, **scene).close()


def test_bundle_memory_roundtrip_and_corruption(lib, ctx):
    require(lib, "vsgl_bundle_write_memory", "vsgl_bundle_read_memory", "vsgl_bundle_scene",
            "vsgl_bundle_settings", "vsgl_bundle_get_info", "vsgl_bundle_destroy")
    s = _scene_with_everything()
    blob = L.bundle_write_memory(ctx, s)
    scene, settings, info = L.bundle_read_memory(ctx, blob)
    _assert_same_scene(s, scene)
    assert info["output_path"] == "" and not info["has_frame"]
    bad = bytearray(blob)
    bad[len(bad) // 2] ^= 0xFF
    with pytest.raises(L.VsglError) as e:
        L.bundle_read_memory(ctx, bytes(bad))
    assert e.value.code == L.Result.ERROR_BAD_FORMAT and e.value.message, e.value.message
    with pytest.raises(L.VsglError) as e:
        L.bundle_read_memory(ctx, blob[: len(blob) // 3])
    assert e.value.code == L.Result.ERROR_BAD_FORMAT


def test_bundle_read_missing_file(lib, ctx, tmp_path):
    require(lib, "vsgl_bundle_read")
    with pytest.raises(L.VsglError) as e:
        L.bundle_read(ctx, str(tmp_path / "nope.vsglb"))
    assert e.value.code == L.Result.ERROR_IO
