"""Cycles one-bounce references of the quality scenes: cache keys, files, loading.

Pure Python + numpy. A reference is one Cycles render (one seed) of a
scene's still at a size, stored as build/quality/refs/<scene>_<W>x<H>_<spp>spp_s<seed>_<key>.npz
with the passes DiffInd, GlossInd, DiffCol, GlossCol (float32 (H, W, 3), row
0 = top) and its metadata (render seconds, Blender version, samples, seed).

key = sha1 of (the scene as Blender renders it, resolution, samples, seed,
Blender's version, the source of the functions that build and render it:
cycles_ref.py's build_blender / blender_material / render_cycles / ... and
render_refs.py's render_passes; for a textured scene also those that make
its textures, TEXTURE_CODE). Anything else in those files can change
without re-rendering.

`ensure(names, size)` renders what is missing by running
tests/quality/render_refs.py in Blender ($BLENDER, default `blender`).
"""
import ast
import hashlib
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
import scenes  # noqa: E402

PASSES = ("DiffInd", "GlossInd", "DiffCol", "GlossCol")
DEFAULT_DIR = os.path.join(ROOT, "build", "quality", "refs")
# the code whose change invalidates every reference (function names per file)
CODE = {
    os.path.join("tests", "blender", "cycles_ref.py"): ("_principled_defaults", "blender_material", "build_blender",
                                                        "render_cycles", "load_exr_rgb", "read_passes_exr"),
    os.path.join("tests", "quality", "render_refs.py"): ("render_passes",),
}

# the code that only textured scenes' renders run (their keys hash it too;
# the others' keys do not, so adding textures re-rendered none of them)
TEXTURE_CODE = {
    os.path.join("tests", "blender", "cycles_textures.py"): ("apply_textures",),
    os.path.join("tests", "quality", "scenes.py"): ("texture_pixels", "polygon_uvs"),
}


def code_digest(code=None):
    """sha1 of the source text of the functions in `code` (default CODE; parsed, not imported)."""
    h = hashlib.sha1()
    for rel, funcs in sorted((code or CODE).items()):
        src = open(os.path.join(ROOT, rel)).read()
        tree = ast.parse(src)
        found = {n.name: ast.get_source_segment(src, n) for n in tree.body if isinstance(n, ast.FunctionDef)}
        for f in funcs:
            if f not in found:
                raise RuntimeError("refs.CODE: %s has no function %s" % (rel, f))
            h.update(found[f].encode())
    return h.hexdigest()


def blender_binary():
    return os.environ.get("BLENDER", "blender")


def blender_env():
    """The environment for Blender: PATH without the directories that hold
    another Python (a pyenv build or a venv puts its bin/ first on PATH when
    it runs this script, and Debian's Blender then takes that Python's
    standard library instead of /usr/lib/python3, whose numpy it needs)."""
    env = dict(os.environ)
    keep = []
    for d in env.get("PATH", "").split(os.pathsep):
        py = os.path.join(d, "python3")
        if d and os.path.exists(py) and not os.path.realpath(py).startswith("/usr/"):
            continue
        keep.append(d)
    env["PATH"] = os.pathsep.join(keep)
    for k in ("PYTHONHOME", "PYTHONPATH", "VIRTUAL_ENV"):
        env.pop(k, None)
    return env


def blender_version(refdir=DEFAULT_DIR):
    """Blender's version string ("3.4.1"), from `blender --version`, cached in
    refdir keyed by the binary's path, size and mtime."""
    import shutil
    exe = shutil.which(blender_binary())
    if exe is None:
        return None
    st = os.stat(exe)
    stamp = "%s %d %d" % (os.path.realpath(exe), st.st_size, int(st.st_mtime))
    cache = os.path.join(refdir, "blender_version.json")
    try:
        d = json.load(open(cache))
        if d.get("stamp") == stamp:
            return d["version"]
    except (OSError, ValueError):
        pass
    out = subprocess.run([exe, "--version"], capture_output=True, text=True, env=blender_env()).stdout
    line = next((l for l in out.splitlines() if l.startswith("Blender ")), None)
    if line is None:
        return None
    version = line.split()[1]
    os.makedirs(refdir, exist_ok=True)
    with open(cache + ".part", "w") as fh:
        json.dump(dict(stamp=stamp, version=version), fh)
    os.replace(cache + ".part", cache)
    return version


def key(case, spp, seed, version, code=None):
    """The cache key of one reference render (case: scenes.case(...))."""
    d = dict(case=scenes.blender_case(case), spp=int(spp), seed=int(seed), version=version,
             code=code or code_digest())
    if case.get("images"):
        d["textures"] = code_digest(TEXTURE_CODE)
    blob = json.dumps(d, sort_keys=True)
    return hashlib.sha1(blob.encode()).hexdigest()[:16]


def path(refdir, name, size, seed, version, code=None):
    w, h, spp = scenes.size_of(size)
    c = scenes.case(name, (w, h))
    k = key(c, spp, seed, version, code)
    return os.path.join(refdir, "%s_%dx%d_%dspp_s%d_%s.npz" % (name, w, h, spp, seed, k))


def path_frame(refdir, name, size, seed, version, anim, frame, code=None):
    """The reference of frame `frame` of animation `anim` ("light" or
    "camera", scenes.animate) at `size`. Frame 0 is the still: the same file
    as path()."""
    w, h, spp = scenes.size_of(size)
    if not frame:
        return path(refdir, name, (w, h, spp), seed, version, code)
    c = scenes.animate(scenes.case(name, (w, h)), anim, frame)
    k = key(c, spp, seed, version, code)
    return os.path.join(refdir, "%s_%s%02d_%dx%d_%dspp_s%d_%s.npz" % (name, anim, frame, w, h, spp, seed, k))


def load(p, names=PASSES):
    """(passes dict, metadata dict) of a reference file."""
    with np.load(p) as z:
        passes = {k: z[k] for k in names}
        meta = json.loads(str(z["meta"]))
    return passes, meta


def save(p, passes, meta, names=PASSES):
    tmp = p + ".part.npz"
    np.savez(tmp, meta=np.array(json.dumps(meta)), **{k: np.asarray(passes[k], np.float32) for k in names})
    os.replace(tmp, p)  # a cache entry is never partial


def missing(names, size, refdir=DEFAULT_DIR, version=None, seeds=scenes.SEEDS):
    version = version or blender_version(refdir)
    code = code_digest()
    return [(n, s) for n in names for s in seeds if not os.path.exists(path(refdir, n, size, s, version, code))]


def ensure(names, size, refdir=DEFAULT_DIR, seeds=scenes.SEEDS, log=None, quiet=False):
    """Make sure every (scene, seed) reference exists; render the missing ones
    in Blender. Returns {name: [(passes, meta) per seed]}. Raises
    RuntimeError if Blender is missing or fails."""
    return ensure_frame(names, size, "light", 0, refdir, seeds, log, quiet)


def mean_combined(name, size, refdir=DEFAULT_DIR):
    """The mean of scene `name`'s two seeds' coloured Combined pass at size
    (w, h, spp), rendered in Blender if missing (ensure)."""
    import metrics  # noqa: E402 (tests/quality, beside this file)
    pairs = ensure([name], size, refdir)[name]
    return 0.5 * sum(metrics.coloured(p)["Combined"] for p, _ in pairs)


def ensure_frames(names, size, anim, frames, refdir=DEFAULT_DIR, seeds=scenes.SEEDS, log=None, quiet=False):
    """Render the missing references of frames `frames` of animation `anim`,
    every scene's in one Blender session (a session's start and scene build
    cost about twice a frame's render at 80 x 60). Loads nothing."""
    version = blender_version(refdir)
    code = code_digest()
    for n in names:
        need = [f for f in frames for s in seeds if version is None
                or not os.path.exists(path_frame(refdir, n, size, s, version, anim, f, code))]
        if need:
            _render(sorted(set(need)), [n], size, anim, refdir, seeds, version, log, quiet)


def ensure_frame(names, size, anim, frame, refdir=DEFAULT_DIR, seeds=scenes.SEEDS, log=None, quiet=False):
    """ensure() for frame `frame` of animation `anim` (0: the still, the
    same files as ensure()'s)."""
    version = blender_version(refdir)
    code = code_digest()
    need = sorted({n for n in names for s in seeds if version is None
                   or not os.path.exists(path_frame(refdir, n, size, s, version, anim, frame, code))})
    if need:
        _render([frame], need, size, anim, refdir, seeds, version, log, quiet)
    out = {}
    for n in names:
        out[n] = []
        for s in seeds:
            p = path_frame(refdir, n, size, s, version, anim, frame, code)
            if not os.path.exists(p):
                raise RuntimeError("reference %s was not written" % p)
            out[n].append(load(p))
    return out


def _render(frames, need, size, anim, refdir, seeds, version, log, quiet):
    """Render frames `frames` of scenes `need` in one Blender session."""
    if version is None:
        raise RuntimeError("references missing and no Blender found ($BLENDER=%s)" % blender_binary())
    sz = size if isinstance(size, str) else "x".join(str(v) for v in scenes.size_of(size))
    cmd = [blender_binary(), "-b", "--factory-startup", "--python-exit-code", "1", "--python",
           os.path.join(HERE, "render_refs.py"), "--", "--size", sz, "--scenes", ",".join(need),
           "--seeds", ",".join(str(s) for s in seeds), "--out", refdir]
    what = "reference(s)"
    if frames != [0]:
        cmd += ["--anim", anim, "--frame", ",".join(str(f) for f in frames)]
        what = "frame(s) %s of the %s animation" % (",".join(str(f) for f in frames), anim)
    if not quiet:
        print("rendering Cycles %s (%d seeds) in Blender %s: %s" % (what, len(seeds), version, " ".join(need)),
              flush=True)
    log = log or os.path.join(refdir, "render_refs.log")
    os.makedirs(refdir, exist_ok=True)
    with open(log, "a") as fh:
        rc = subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, cwd=ROOT, env=blender_env()).returncode
    if rc != 0:
        raise RuntimeError("render_refs.py failed (exit %d); see %s" % (rc, log))
