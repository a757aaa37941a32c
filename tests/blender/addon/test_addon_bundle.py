"""File > Export > VSGL scene bundle: the file read back by the library holds
what the export produced (and the settings)."""
import os

import bpy
import numpy as np
import pytest

from conftest import room
from vsgl_indirect import export, operators


def test_export_bundle_round_trip(scene, tmp_path):
    if not operators._bundle_available():
        pytest.skip("libvsgl has no vsgl_bundle_write yet")
    from vsgl_indirect import libvsgl
    room(scene)
    scene.vsgl_indirect.use_advanced = True
    scene.vsgl_indirect.rsm_resolution = 128
    scene.vsgl_indirect.fit_mode = "FIS"
    path = str(tmp_path / "scene.vsglb")
    assert bpy.ops.vsgl.export_bundle(filepath=path) == {"FINISHED"}
    sd = export.collect(bpy.context.evaluated_depsgraph_get(), scene)
    ctx = libvsgl.Context()
    arrays, settings, info = libvsgl.bundle_read(ctx, path)
    assert np.array_equal(arrays["positions"], sd.positions)
    assert np.array_equal(arrays["indices"], sd.indices)
    assert np.array_equal(arrays["material_indices"], sd.material_indices)
    assert len(arrays["lights"]) == len(sd.lights) == 1
    assert arrays["lights"][0].power == pytest.approx(sd.lights[0]["power"])
    assert arrays["camera"].width == 32 and arrays["camera"].height == 24
    assert settings.rsm_resolution == 128 and settings.fit_mode == libvsgl.FitMode.FIS
    ctx.close()


def test_export_bundle_bad_scene_reports(scene, tmp_path):
    if not operators._bundle_available():
        pytest.skip("libvsgl has no vsgl_bundle_write yet")
    path = str(tmp_path / "empty.vsglb")
    with pytest.raises(RuntimeError, match="no active camera"):
        bpy.ops.vsgl.export_bundle(filepath=path)
    assert not os.path.exists(path)
