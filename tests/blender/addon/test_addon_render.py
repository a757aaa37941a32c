"""The add-on inside real background renders (-f, -a, parallel processes),
the compositor wiring, error reports, the preview operator and the
``--addons`` install route. Tiny images, 1 sample: wiring, not quality."""
import os
import shutil
import subprocess

import bpy
import numpy as np
import pytest

from conftest import (IS_BINARY, REPO, camera, light, link, plane, real_render_or_skip, render, shader_material,
                      room, save)
from exr_read import read_exr, read_pass
from vsgl_indirect import compat, compositor, engine, handlers, runner

W, H = 32, 24


def setup_blend(scene, tmp, name="t.blend", add=True, **kw):
    room(scene, str(tmp / "aov" / "{scene}_{view_layer}_####.exr"))
    scene.vsgl_indirect.add_to_render = add
    scene.render.filepath = str(tmp / "out" / "beauty_")
    for k, v in kw.items():
        setattr(scene.vsgl_indirect, k, v)
    return save(str(tmp / name))


def image(path):
    im = bpy.data.images.load(path, check_existing=False)
    px = np.array(im.pixels[:], np.float32).reshape(im.size[1], im.size[0], 4)[::-1]
    bpy.data.images.remove(im)
    return px  # rows from the top, like the AOV


def aov(tmp, frame):
    return str(tmp / "aov" / ("Scene_ViewLayer_%04d.exr" % frame))


def test_handler_fake_renderer_two_frames_composited(scene, tmp_path):
    """-a over 2 frames: each frame's own file is written before compositing
    and the composite equals render + that frame's Combined."""
    path = setup_blend(scene, tmp_path)
    scene.objects["Spot"].data.energy = 1e-9   # beauty ~ black (world is None)
    save(path)
    r = render(path, (1, 2), env={"VSGL_TEST_FAKE_RENDER": "1"})
    assert r.returncode == 0, r.stdout
    assert "VSGL ERROR" not in r.stdout, r.stdout
    for f in (1, 2):
        comb = read_pass(aov(tmp_path, f), "VSGL.Combined", "RGBA")
        assert comb.shape == (H, W, 4)
        assert np.allclose(comb[..., :3], (0.1 * f, 0.2, 0.3), atol=1e-3)   # half float (the default)
        out = image(str(tmp_path / "out" / ("beauty_%04d.exr" % f)))
        assert np.allclose(out[..., :3], (0.1 * f, 0.2, 0.3), atol=1e-3), (f, out[0, 0])


def test_aov_passes_default_and_colour_passes(scene, tmp_path):
    """The AOV holds what the compositor setup reads, 16 half channels
    (DiffInd, GlossInd, Diff, Gloss, Combined + alpha); Colour Passes adds
    the library's DiffCol and GlossCol (22). The compositor wiring works
    either way (the Image node's sockets come from the same pass set)."""
    path = setup_blend(scene, tmp_path)
    scene.objects["Spot"].data.energy = 1e-9   # beauty ~ black (world is None)
    want = {"VSGL.%s.%s" % (p, c) for p in ("DiffInd", "GlossInd", "Diff", "Gloss") for c in "RGB"}
    want |= {"VSGL.Combined.%s" % c for c in "RGBA"}
    for colour in (False, True):
        scene.vsgl_indirect.color_passes = colour
        save(path)
        r = render(path, 1, env={"VSGL_TEST_FAKE_RENDER": "1"})
        assert r.returncode == 0 and "VSGL ERROR" not in r.stdout, r.stdout
        ch, _ = read_exr(aov(tmp_path, 1))
        extra = {"VSGL.%s.%s" % (p, c) for p in ("DiffCol", "GlossCol") for c in "RGB"} if colour else set()
        assert set(ch) == want | extra, sorted(set(ch) ^ (want | extra))
        out = image(str(tmp_path / "out" / "beauty_0001.exr"))
        assert np.allclose(out[..., :3], (0.1, 0.2, 0.3), atol=1e-3), (colour, out[0, 0])


def test_real_render_composite_is_render_plus_aov(scene, tmp_path):
    real_render_or_skip()
    path = setup_blend(scene, tmp_path)
    r = render(path, 1)
    assert r.returncode == 0 and "VSGL INFO: wrote" in r.stdout, r.stdout
    comp = image(str(tmp_path / "out" / "beauty_0001.exr"))
    a = read_pass(aov(tmp_path, 1), "VSGL.Combined", "RGB")
    assert np.all(np.isfinite(a)) and a.max() > 0 and a.min() >= 0
    # Same scene without the Add node: the plain render.
    scene.vsgl_indirect.add_to_render = False
    scene.render.filepath = str(tmp_path / "plain" / "beauty_")
    save(path)
    r = render(path, 1)
    assert r.returncode == 0, r.stdout
    plain = image(str(tmp_path / "plain" / "beauty_0001.exr"))
    assert np.allclose(comp[..., :3] - plain[..., :3], a, atol=2e-3, rtol=1e-3)


def test_parallel_processes_write_distinct_identical_files(scene, tmp_path):
    real_render_or_skip()
    path = setup_blend(scene, tmp_path, threads=1)
    env = dict(os.environ)
    procs = []
    for f in (3, 4):
        if IS_BINARY:
            cmd = [bpy.app.binary_path, "-b", "--factory-startup", path, "--python",
                   os.path.join(REPO, "tests", "blender", "bootstrap_addon.py"), "-f", str(f)]
        else:
            import sys
            cmd = [sys.executable, os.path.join(os.path.dirname(__file__), "bpy_render.py"),
                   path, str(f)]
        procs.append(subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, universal_newlines=True))
    logs = [p.communicate(timeout=240)[0] for p in procs]
    assert all(p.returncode == 0 for p in procs), logs
    a3, a4 = aov(tmp_path, 3), aov(tmp_path, 4)
    assert os.path.exists(a3) and os.path.exists(a4) and a3 != a4
    c3, _ = read_exr(a3)
    c4, _ = read_exr(a4)
    assert sorted(c3) == sorted(c4)
    for k in c3:            # static scene, deterministic library: same pixels
        assert np.array_equal(c3[k], c4[k]), k
    assert c3["VSGL.Combined.R"].max() > 0


def test_farm_race_overlapping_frames_never_composite_a_placeholder(scene, tmp_path):
    """Issue 10: 4 workers share one AOV template and render overlapping
    frames (a requeued task while its first worker still runs). render_pre
    used to overwrite another worker's finished AOV with a black placeholder:
    4 to 12 of 32 composites came out black or failed with 'Cannot read'.
    Every composite must be its frame's AOV (fake renderer: 0.1 f, 0.2, 0.3
    on a black beauty), and no worker may log an error."""
    path = setup_blend(scene, tmp_path)
    scene.objects["Spot"].data.energy = 1e-9   # beauty ~ black (world is None)
    scene.render.image_settings.file_format = "OPEN_EXR"
    save(path)
    frames = (1, 6)
    workers = 4
    farm = os.path.join(os.path.dirname(__file__), "farm_output.py")
    procs = []
    for w in range(workers):
        e = dict(os.environ, VSGL_TEST_FAKE_RENDER="1", VSGL_TEST_OUT=str(tmp_path / ("w%d" % w) / "beauty_"))
        if IS_BINARY:
            cmd = [bpy.app.binary_path, "-b", "--factory-startup", path, "--python",
                   os.path.join(REPO, "tests", "blender", "bootstrap_addon.py"), "--python", farm,
                   "-s", str(frames[0]), "-e", str(frames[1]), "-t", "1", "-a"]
        else:
            import sys
            cmd = [sys.executable, os.path.join(os.path.dirname(__file__), "bpy_render.py"), path,
                   "%d:%d" % frames, farm]
        procs.append(subprocess.Popen(cmd, env=e, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                      universal_newlines=True))
    logs = [p.communicate(timeout=600)[0] for p in procs]
    wrong = []
    for w in range(workers):
        assert procs[w].returncode == 0, logs[w]
        for f in range(frames[0], frames[1] + 1):
            out = str(tmp_path / ("w%d" % w) / ("beauty_%04d.exr" % f))
            if not os.path.exists(out):
                wrong.append("worker %d frame %d: no composite" % (w, f))
                continue
            px = image(out)
            if not np.allclose(px[..., :3], (0.1 * f, 0.2, 0.3), atol=1e-3):
                wrong.append("worker %d frame %d: composite %s" % (w, f, px[0, 0, :3]))
        bad = [line for line in logs[w].splitlines() if "VSGL ERROR" in line or "Cannot read" in line
               or "Traceback" in line]
        if bad:
            wrong.append("worker %d: %s" % (w, bad[:3]))
    n = workers * (frames[1] - frames[0] + 1)
    if wrong and os.environ.get("VSGL_TEST_FARM_LOGS"):
        for w in range(workers):
            print("---- worker %d\n%s" % (w, logs[w]))
    assert not wrong, "%d of %d composites wrong or errors:\n%s" % (len(wrong), n, "\n".join(wrong))


def test_failed_frame_retires_only_a_previous_runs_aov(scene, tmp_path):
    """Without placeholders, a frame whose AOV cannot be computed must still
    not composite a previous run's file: it is retired (and reported); a
    file written during this job by another worker would stay."""
    path = setup_blend(scene, tmp_path)
    r = render(path, 1, env={"VSGL_TEST_FAKE_RENDER": "1"})
    assert r.returncode == 0 and os.path.exists(aov(tmp_path, 1)), r.stdout
    os.utime(aov(tmp_path, 1), (1, 1))          # a previous run's file
    bpy.data.objects.remove(scene.objects["Spot"])
    save(path)
    r = render(path, 1, env={"VSGL_TEST_FAKE_RENDER": "1"})
    assert r.returncode == 0 and "no light with non-zero power" in r.stdout, r.stdout
    assert "removed the previous run's AOV" in r.stdout, r.stdout
    assert not os.path.exists(aov(tmp_path, 1))
    assert not [n for n in os.listdir(str(tmp_path / "aov")) if "retired" in n or ".setup-" in n]


def test_placeholder_and_stale_removal_keep_other_writers_files(tmp_path):
    """The two removals of handlers.py never delete a file another process
    renamed over the path (the farm race of issue 10)."""
    p = str(tmp_path / "f_0001.exr")
    with open(p, "w") as f:
        f.write("placeholder")
    ino = os.stat(p).st_ino
    other = str(tmp_path / "other")
    with open(other, "w") as f:
        f.write("real AOV")
    os.replace(other, p)                        # another worker's atomic write
    assert not handlers.remove_if_inode(p, ino) and open(p).read() == "real AOV"
    assert handlers.remove_if_inode(p, os.stat(p).st_ino) and not os.path.exists(p)
    with open(p, "w") as f:
        f.write("fresh")
    assert not handlers.retire_stale(p, os.stat(p).st_mtime - 10) and os.path.exists(p)
    assert handlers.retire_stale(p, os.stat(p).st_mtime + 10) and not os.path.exists(p)
    assert os.listdir(str(tmp_path)) == []


def test_bad_scene_reported_render_continues(scene, tmp_path):
    link(scene, plane("Floor", 4))
    camera(scene)
    scene.vsgl_indirect.enabled = True
    scene.vsgl_indirect.output_path = str(tmp_path / "aov" / "x_####.exr")
    scene.render.filepath = str(tmp_path / "out" / "beauty_")
    path = save(str(tmp_path / "nolight.blend"))
    r = render(path, 1, env={"VSGL_TEST_FAKE_RENDER": "1"})
    assert r.returncode == 0, r.stdout
    assert "VSGL ERROR" in r.stdout and "no light with non-zero power" in r.stdout, r.stdout
    assert os.path.exists(str(tmp_path / "out" / "beauty_0001.exr"))
    assert not os.path.exists(str(tmp_path / "aov" / "x_0001.exr"))  # no black stand-in


def test_library_missing_registers_and_reports(scene, tmp_path):
    path = setup_blend(scene, tmp_path)
    r = render(path, 1, env={"VSGL_LIBRARY": str(tmp_path / "nope" / "libvsgl.so")})
    assert r.returncode == 0, r.stdout
    assert "VSGL ERROR" in r.stdout and "VSGL_LIBRARY" in r.stdout, r.stdout
    assert os.path.exists(str(tmp_path / "out" / "beauty_0001.exr"))


def test_unwritable_output_path_reported(scene, monkeypatch):
    room(scene, "/proc/vsgl_cannot_write/x_####.exr")
    monkeypatch.setattr(engine, "RENDER_OVERRIDE", lambda sd, o: pytest.fail("rendered"))
    res = runner.run_frame(scene, bpy.context.evaluated_depsgraph_get(), 1)
    assert res is None
    err = runner.LAST_RUN[scene.name]["error"]
    assert "/proc/vsgl_cannot_write" in err and "frame 1" in err


def _nodes(tree, prefix):
    return [n for n in tree.nodes if n.name.startswith(prefix)]


def test_compositor_setup_idempotent_and_removable(scene, tmp_path):
    room(scene, str(tmp_path / "aov" / "{scene}_{view_layer}_####.exr"))
    scene.render.filepath = str(tmp_path / "out" / "b_")
    tree = compat.compositor_tree(scene, create=True)
    user = [n for n in tree.nodes]
    for _ in range(3):
        assert handlers.setup_scene(scene) == []
        # the sockets' placeholder is gone again, and nothing beside it
        assert os.listdir(str(tmp_path / "aov")) == [handlers.SETUP_LOCK], os.listdir(str(tmp_path / "aov"))
    assert len(_nodes(tree, "VSGL Indirect [")) == 1 and len(_nodes(tree, "VSGL Add ")) == 2
    assert len(_nodes(tree, "VSGL Frame")) == 1
    out = compat.compositor_output_socket(tree)
    assert out.links[0].from_node.name == "VSGL Add Glossy [ViewLayer]"
    node = tree.nodes["VSGL Indirect [ViewLayer]"]
    assert {"DiffInd", "GlossInd", "Diff", "Gloss", "Combined"} <= set(node.outputs.keys())
    assert node.image.source == "SEQUENCE"
    # Explained, not shown: the frame numbers are hidden with the options.
    assert not node.show_options and "file number = frame" in node.label
    # Every VSGL node inside the labelled frame, which is beside (below) the
    # user's nodes, not over them.
    frame = tree.nodes["VSGL Frame"]
    assert "VSGL" in frame.label
    ours = [n for n in tree.nodes if n.name.startswith("VSGL ") and n != frame]
    assert all(n.parent == frame for n in ours)
    theirs = [n for n in tree.nodes if not n.name.startswith("VSGL ")]
    assert {n.name for n in theirs} == {n.name for n in user if not n.name.startswith("VSGL ")}
    x0, y0, x1, y1 = compositor._bounds(theirs)
    for n in ours:
        nx, ny = compositor._absolute(n)
        assert ny <= y0, (n.name, (nx, ny), (x0, y0, x1, y1))   # top below their bottom

    # Strength and per-pass toggles: the Add nodes' factors.
    def facs():
        return [compositor.compat.add_node_sockets(tree.nodes["VSGL Add %s [ViewLayer]" % k])
                for k in ("Diffuse", "Glossy")]

    def factor(add):
        if add.bl_idname == "ShaderNodeMix":
            return [s for s in add.inputs if s.name == "Factor" and s.enabled][0].default_value
        return add.inputs[0].default_value
    adds = [tree.nodes["VSGL Add %s [ViewLayer]" % k] for k in ("Diffuse", "Glossy")]
    assert [round(factor(a), 6) for a in adds] == [1.0, 1.0]
    assert adds[0].inputs and compat.add_node_sockets(adds[0])[1].links[0].from_socket.name == "Diff"
    assert compat.add_node_sockets(adds[1])[1].links[0].from_socket.name == "Gloss"
    scene.vsgl_indirect.strength = 0.5
    scene.vsgl_indirect.use_glossy = False
    assert handlers.setup_scene(scene) == []
    assert [round(factor(a), 6) for a in adds] == [0.5, 0.0]
    assert "(off)" in adds[1].label
    # A slider drag only touches the factors (update_grading, the callback).
    from vsgl_indirect.config import Options
    assert compositor.update_grading(scene, Options(strength=0.25, use_diffuse=False))
    assert [round(factor(a), 6) for a in adds] == [0.0, 0.25]
    scene.vsgl_indirect.add_to_render = False
    handlers.setup_scene(scene)
    assert not _nodes(tree, "VSGL Add")
    assert out.links[0].from_node.bl_idname == "CompositorNodeRLayers"
    compositor.remove(scene)
    assert not _nodes(tree, "VSGL")
    assert out.links[0].from_node.bl_idname == "CompositorNodeRLayers"
    assert not compositor.update_grading(scene, Options())


def test_compositor_replaces_the_old_single_add_node(scene, tmp_path):
    """Files set up before issue 15 have one 'VSGL Add [layer]' of Combined."""
    room(scene, str(tmp_path / "aov" / "{scene}_{view_layer}_####.exr"))
    scene.render.filepath = str(tmp_path / "out" / "b_")
    compositor.remove(scene)      # what the update callback set up (inside Blender)
    tree = compat.compositor_tree(scene, create=True)
    out = compat.compositor_output_socket(tree)
    rl = out.links[0].from_node.name
    add, a, b, res = compat.new_add_node(tree)
    add.name = "VSGL Add [ViewLayer]"
    tree.links.new(tree.nodes[rl].outputs["Image"], a)
    tree.links.new(res, out)
    assert handlers.setup_scene(scene) == []
    assert "VSGL Add [ViewLayer]" not in tree.nodes
    chain, n = [], out.links[0].from_node
    while n.name.startswith("VSGL Add"):
        chain.append(n.name)
        n = compat.add_node_sockets(n)[0].links[0].from_node
    assert chain == ["VSGL Add Glossy [ViewLayer]", "VSGL Add Diffuse [ViewLayer]"] and n.name == rl


def test_settings_update_callbacks_only_in_the_application():
    """Edits rewire the compositor through update= callbacks inside Blender;
    the pip bpy module gets none (its 4.2 LTS build segfaults at exit with
    them; render_init sets the compositor up there)."""
    from vsgl_indirect import settings as st
    assert st.IN_APPLICATION == IS_BINARY
    assert bool(st._UPDATE) == IS_BINARY


def test_process_with_the_addon_exits_cleanly(tmp_path):
    """Issue 10: the pip bpy 4.2.23 module exited with a segfault (139) after
    every render while the add-on was registered (any Python callable left
    in Blender at exit: update= callbacks, app handlers)."""
    import sys
    code = ("import sys; sys.path.insert(0, %r); import bpy, vsgl_indirect; vsgl_indirect.register(); "
            "s = bpy.context.scene; s.vsgl_indirect.enabled = True; print('ok')" % os.path.join(REPO, "addon"))
    if IS_BINARY:
        cmd = [bpy.app.binary_path, "-b", "--factory-startup", "--python-expr", code]
    else:
        cmd = [sys.executable, "-c", code]
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=120)
    assert r.returncode == 0 and "ok" in r.stdout, (r.returncode, r.stdout[-2000:])


def test_preview_operator_writes_and_loads_image(scene, monkeypatch):
    room(scene)
    calls = []

    def fake(sd, options):
        calls.append(sd.summary())
        z = np.full((sd.height, sd.width, 3), 0.5, np.float32)
        return {p: z for p in engine.PLANES if p != "alpha"}, {"skipped": "light 'X': test"}
    if engine.library_error():
        monkeypatch.setattr(engine, "RENDER_OVERRIDE", fake)
    assert bpy.ops.vsgl.preview_indirect() == {"FINISHED"}
    img = bpy.data.images["VSGL Preview"]
    assert os.path.exists(bpy.path.abspath(img.filepath))
    info = runner.LAST_RUN[scene.name]
    assert info["status"] == "done" and info["timings"]["export"] >= 0


def test_addons_route_with_user_scripts(scene, tmp_path):
    """blender -b file --addons vsgl_indirect -f 1 with the add-on zip
    installed in BLENDER_USER_SCRIPTS (library from its lib/)."""
    if not IS_BINARY:
        pytest.skip("--addons is an option of the Blender binary; the pip bpy module has no CLI")
    import zipfile
    r = subprocess.run([os.path.join(REPO, "tools", "build_addon.sh")], cwd=REPO,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    assert r.returncode == 0, r.stdout
    # What Preferences > Add-ons > Install does with the zip.
    zipfile.ZipFile(os.path.join(REPO, "build", "vsgl_indirect.zip")).extractall(
        str(tmp_path / "scripts" / "addons"))
    dst = tmp_path / "scripts" / "addons" / "vsgl_indirect"
    assert (dst / "lib" / "libvsgl.so").exists() and (dst / "blender_manifest.toml").exists()
    path = setup_blend(scene, tmp_path)
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(tmp_path / "scripts"))
    env.pop("VSGL_LIBRARY", None)
    r = subprocess.run([bpy.app.binary_path, "-b", "--factory-startup", path, "--addons",
                        "vsgl_indirect", "-f", "1"], env=env, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, universal_newlines=True, timeout=240)
    assert r.returncode == 0, r.stdout
    if engine.library_error():
        assert "VSGL ERROR" in r.stdout and "vsgl_render" in r.stdout, r.stdout
    else:
        assert "VSGL INFO: wrote" in r.stdout and str(dst / "lib") in r.stdout or \
            os.path.exists(aov(tmp_path, 1)), r.stdout
        assert os.path.exists(aov(tmp_path, 1))


def test_render_depsgraph_per_view_layer(scene, tmp_path):
    """The AOV uses the render depsgraph of each view layer: eye-hidden objects
    render, subdivision uses its render level, excluded collections do not."""
    room(scene, str(tmp_path / "aov" / "{view_layer}_####.exr"))
    scene.render.filepath = str(tmp_path / "out" / "b_")
    col = bpy.data.collections.new("Extra")
    scene.collection.children.link(col)
    from conftest import cube
    col.objects.link(cube("Box", 1.0, (0, 1, 0.5)))
    second = scene.view_layers.new("Second")
    second.layer_collection.children["Extra"].exclude = True
    ob = link(scene, cube("EyeHidden", 0.5, (1, 0, 0.25)))
    sub = ob.modifiers.new("S", "SUBSURF")
    sub.levels, sub.render_levels = 0, 2
    bpy.context.view_layer.update()
    ob.hide_set(True)
    path = save(str(tmp_path / "vl.blend"))
    r = render(path, 1, env={"VSGL_TEST_FAKE_RENDER": "1"})
    assert r.returncode == 0, r.stdout
    # floor 2 + wall 2 + box 12 + subdivided cube at level 2: 6 * 16 * 2
    assert "ViewLayer_0001.exr (208 triangles" in r.stdout, r.stdout
    assert "Second_0001.exr (196 triangles" in r.stdout, r.stdout
    assert os.path.exists(str(tmp_path / "aov" / "Second_0001.exr"))


def test_extension_zip_install(scene, tmp_path):
    """The zip from tools/build_addon.sh installs as a 4.2+ extension
    (blender_manifest.toml) and renders with the library it carries."""
    if bpy.app.version < (4, 2, 0):
        pytest.skip("extensions (blender_manifest.toml) need Blender 4.2+")
    real_render_or_skip()
    import sys
    zip_path = str(tmp_path / "vsgl_indirect.zip")
    r = subprocess.run([os.path.join(REPO, "tools", "build_addon.sh")], cwd=REPO,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    assert r.returncode == 0, r.stdout
    shutil.copy(os.path.join(REPO, "build", "vsgl_indirect.zip"), zip_path)
    path = setup_blend(scene, tmp_path)
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "home"))
    env.pop("VSGL_LIBRARY", None)
    r = subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__),
                                                     "ext_install_render.py"), zip_path, path],
                       env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True, timeout=240)
    assert r.returncode == 0, r.stdout
    assert "install {'FINISHED'}" in r.stdout, r.stdout
    assert "/lib/libvsgl.so" in r.stdout and "STATUS (True" in r.stdout, r.stdout
    assert "VSGL INFO: wrote" in r.stdout and os.path.exists(aov(tmp_path, 1)), r.stdout


def test_compute_in_thread_releases_gil_and_cancels(scene, tmp_path):
    """What the Preview operator relies on: the C render runs in a worker
    thread while Python keeps running, and the progress callback cancels."""
    real_render_or_skip()
    import threading
    import time
    from vsgl_indirect import export
    from vsgl_indirect.config import Options
    room(scene)
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    bpy.context.view_layer.update()
    sd = export.collect(bpy.context.evaluated_depsgraph_get(), scene)
    opts = Options(preset="BALANCED")
    done, ticks, stages = {}, [0], []

    def work():
        done["res"] = engine.compute(sd, opts, str(tmp_path / "t.exr"),
                                     progress=lambda st, f: stages.append(st) and False)
    t = threading.Thread(target=work)
    t0 = time.perf_counter()
    t.start()
    while t.is_alive():
        ticks[0] += 1
        time.sleep(0.001)
    elapsed = time.perf_counter() - t0
    assert os.path.exists(str(tmp_path / "t.exr")) and stages
    # Main thread kept ticking through the render (~1 tick per ms if the GIL is free).
    assert ticks[0] > 0.3 * elapsed * 1000, (ticks[0], elapsed)
    with pytest.raises(engine.AovError, match="cancelled"):
        engine.compute(sd, opts, str(tmp_path / "c.exr"), progress=lambda st, f: True)
    assert not os.path.exists(str(tmp_path / "c.exr"))


def _diffuse(name, color):
    mat, d = shader_material(name, "ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = color + (1.0,)
    return mat


@pytest.mark.parametrize("fit,shift,ctype", [("AUTO", (0.0, 0.0), "PERSP"),
                                             ("VERTICAL", (0.15, -0.1), "PERSP"),
                                             ("HORIZONTAL", (0.05, 0.1), "ORTHO")])
def test_aov_diffcol_aligns_with_cycles_diffcol(scene, tmp_path, fit, shift, ctype):
    """Camera, transforms and materials at once: the AOV's DiffCol plane must
    match Cycles' own DiffCol pass pixel for pixel (away from edges)."""
    real_render_or_skip()
    scene.render.resolution_x, scene.render.resolution_y = 64, 40
    scene.cycles.samples = 16
    scene.view_layers[0].use_pass_diffuse_color = True
    cols = {"Floor": (0.8, 0.2, 0.1), "Wall": (0.1, 0.6, 0.3), "Box": (0.2, 0.3, 0.9)}
    link(scene, plane("Floor", 8, (0, 0, 0), _diffuse("F", cols["Floor"])))
    wall = link(scene, plane("Wall", 8, (0, 3, 2), _diffuse("W", cols["Wall"])))
    wall.rotation_euler = (1.5708, 0, 0)
    from conftest import cube
    box = link(scene, cube("Box", 1.0, (0.8, 0.5, 0.5), _diffuse("B", cols["Box"])))
    box.rotation_euler = (0, 0, 0.6)
    box.scale = (1.5, 1, 1)
    cam = camera(scene, (0.5, -5, 1.8), (1.35, 0, 0.1), lens=30)
    cam.data.sensor_fit = fit
    cam.data.shift_x, cam.data.shift_y = shift
    cam.data.type = ctype
    cam.data.ortho_scale = 6.0
    light(scene, "POINT", "Lamp", 300.0, (0, -1, 3))
    scene.vsgl_indirect.output_path = str(tmp_path / "aov" / "a_####.exr")
    scene.vsgl_indirect.add_to_render = False
    scene.vsgl_indirect.color_passes = True   # the library's DiffCol, not written by default
    scene.vsgl_indirect.enabled = True
    # The compositor routes Cycles' DiffCol pass to the saved image.
    tree = compat.compositor_tree(scene, create=True)
    rl = [n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"][0]
    src = rl.outputs.get("DiffCol") or rl.outputs["Diffuse Color"]   # 5.0 renamed it
    tree.links.new(src, compat.compositor_output_socket(tree))
    scene.render.filepath = str(tmp_path / "out" / "ml_")
    path = save(str(tmp_path / "align.blend"))
    r = render(path, 1)
    assert r.returncode == 0 and "VSGL INFO: wrote" in r.stdout, r.stdout
    ours = read_pass(str(tmp_path / "aov" / "a_0001.exr"), "VSGL.DiffCol")
    ref = image(str(tmp_path / "out" / "ml_0001.exr"))[..., :3]
    assert ours.shape == ref.shape
    # Interior pixels: all 8 neighbours have the same Cycles colour.
    flat = np.ones(ref.shape[:2], bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            flat &= np.all(np.abs(np.roll(np.roll(ref, dy, 0), dx, 1) - ref) < 1e-3, axis=2)
    flat[[0, -1], :] = flat[:, [0, -1]] = False
    assert flat.sum() > 0.5 * flat.size
    diff = np.abs(ours - ref).max(axis=2)[flat]
    assert np.mean(diff < 0.02) > 0.98, (np.mean(diff < 0.02), np.percentile(diff, 99))


def test_animation_exports_each_frames_state(scene, tmp_path):
    """-a over animated geometry and lights: each frame's AOV is computed from
    that frame's render depsgraph (not the frame the file was saved at)."""
    path = setup_blend(scene, tmp_path)
    from conftest import cube
    box = link(scene, cube("Mover", 1.0, (0, 0, 0.5)))
    for f, x in ((1, 1.0), (3, 9.0)):           # rendered frames are the keyed ones
        box.location.x = x
        box.keyframe_insert("location", index=0, frame=f)
    extra = scene.objects["Spot"].copy()
    extra.hide_render = True
    extra.keyframe_insert("hide_render", frame=1)
    extra.hide_render = False
    extra.keyframe_insert("hide_render", frame=3)
    scene.collection.objects.link(extra)
    scene.frame_set(1)
    path = save(path)
    r = render(path, (1, 3), env={"VSGL_TEST_FAKE_RENDER": "bounds"})
    assert r.returncode == 0 and "VSGL ERROR" not in r.stdout, r.stdout
    for f in (1, 3):
        c = read_pass(aov(tmp_path, f), "VSGL.Combined", "RGB")[0, 0]
        assert c[2] == f
        assert c[0] == pytest.approx(max(4.0, 4 * f - 3 + 0.5), abs=1e-4), (f, c)
        assert c[1] == (1 if f == 1 else 2), (f, c)


def test_export_passes_one_multilayer_exr_per_frame(scene, tmp_path):
    """Export Passes: a File Output node writes the render's passes
    (Blender's names), the VSGL passes and the composite into one
    multilayer EXR per frame; removed again when the option is off."""
    path = setup_blend(scene, tmp_path, export_passes=True,
                       export_path=str(tmp_path / "passes" / "{scene}_"))
    scene.view_layers[0].use_pass_diffuse_direct = True
    scene.objects["Spot"].data.energy = 1e-9
    save(path)
    r = render(path, (1, 2), env={"VSGL_TEST_FAKE_RENDER": "1"})
    assert r.returncode == 0, r.stdout[-3000:]
    assert "VSGL ERROR" not in r.stdout, r.stdout
    for f in (1, 2):
        p = str(tmp_path / "passes" / ("Scene_%04d.exr" % f))
        assert os.path.exists(p), os.listdir(str(tmp_path))
        ch, _ = read_exr(p)
        names = set(ch)
        for want in ("ViewLayer.Combined.R", "ViewLayer.Combined.A", "ViewLayer.DiffDir.R",
                     "ViewLayer.VSGL_DiffInd.R", "ViewLayer.VSGL_Combined.G",
                     "ViewLayer.VSGL_Diff.B", "Composite.R"):
            assert want in names, (want, sorted(names))
        assert np.allclose(ch["ViewLayer.VSGL_Combined.R"], 0.1 * f, atol=1e-3)
        assert np.allclose(ch["Composite.R"], 0.1 * f, atol=2e-3)
    scene.vsgl_indirect.export_passes = False
    handlers.setup_scene(scene)
    assert compositor.FILE_OUTPUT_NODE not in compat.compositor_tree(scene).nodes


@pytest.mark.parametrize("fail", [True, False])
def test_fail_render_without_aov_exits_non_zero(scene, tmp_path, fail):
    """Farms: with 'Fail Render Without AOV' a frame whose AOV cannot be
    computed stops `blender -b -a` with a non-zero status before that frame
    is written; without it the render goes on and logs VSGL ERROR."""
    path = setup_blend(scene, tmp_path, fail_render=fail)
    scene.render.image_settings.file_format = "PNG"
    save(path)
    r = render(path, (1, 3), env={"VSGL_TEST_FAKE_RENDER": "fail"})
    out = sorted(os.listdir(str(tmp_path / "out")))
    assert "test: the fake renderer fails from frame 2 on" in r.stdout, r.stdout[-3000:]
    if fail:
        assert r.returncode == handlers.FAIL_EXIT_CODE, (r.returncode, r.stdout[-3000:])
        assert "stopping the render (exit status 1)" in r.stdout
        assert out == ["beauty_0001.png"], out
    else:
        assert r.returncode == 0, r.stdout[-3000:]
        assert out == ["beauty_0001.png", "beauty_0002.png", "beauty_0003.png"], out


def test_export_passes_with_two_view_layers_setup_and_removal(scene, tmp_path):
    """A second rendered view layer gets its own Render Layers node for the
    passes file, inside the frame, and removal takes it away again."""
    room(scene, str(tmp_path / "aov" / "{scene}_{view_layer}_####.exr"))
    scene.render.filepath = str(tmp_path / "out" / "b_")
    scene.view_layers.new("Second")
    scene.vsgl_indirect.export_passes = True
    assert handlers.setup_scene(scene) == []
    tree = compat.compositor_tree(scene, create=False)
    fo = tree.nodes[compositor.FILE_OUTPUT_NODE]
    names = compat.file_output_names(fo)
    assert "ViewLayer.Combined" in names and "Second.Combined" in names, names
    assert "Second.VSGL_DiffInd" in names and names[-1] == "Composite", names
    rl2 = tree.nodes["VSGL Render Layers [Second]"]
    assert rl2.parent == tree.nodes["VSGL Frame"] and fo.parent == tree.nodes["VSGL Frame"]
    assert handlers.setup_scene(scene) == []          # idempotent
    assert compat.file_output_names(fo) == names
    assert len([n for n in tree.nodes if n.bl_idname == "CompositorNodeOutputFile"]) == 1
    compositor.remove(scene)
    assert not [n for n in tree.nodes if n.name.startswith("VSGL")]
    out = compat.compositor_output_socket(tree)
    assert out.is_linked and out.links[0].from_node.bl_idname == "CompositorNodeRLayers"
