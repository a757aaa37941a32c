"""Register the add-on from the checkout (``blender -b f.blend --python this -f 1``).

Adds ``addon/`` to sys.path and calls ``vsgl_indirect.register()``. With
``VSGL_TEST_FAKE_RENDER=1`` the C renderer is replaced by a deterministic
fake (constant planes depending on the frame; with ``=bounds`` they encode the
exported geometry's max x and the light count; with ``=fail`` frames from 2 on
fail) so compositor wiring and the
per-frame export can be tested independently of libvsgl's numbers.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.normpath(os.path.join(HERE, "..", "..", "addon")))

import vsgl_indirect  # noqa: E402

vsgl_indirect.register()

if os.environ.get("VSGL_TEST_FAKE_RENDER"):
    import numpy as np
    from vsgl_indirect import engine

    def fake(sd, options):
        import bpy
        f = bpy.context.scene.frame_current
        if os.environ["VSGL_TEST_FAKE_RENDER"] == "fail" and f >= 2:
            raise engine.AovError("test: the fake renderer fails from frame 2 on")
        h, w = sd.height, sd.width
        planes = {p: np.zeros((h, w, 3), np.float32) for p in engine.PLANES if p != "alpha"}
        planes["combined"][:] = (0.1 * f, 0.2, 0.3)
        if os.environ["VSGL_TEST_FAKE_RENDER"] == "bounds":
            # Encode what was exported: max x of the geometry, light count.
            planes["combined"][:] = (float(sd.positions[:, 0].max()), len(sd.lights), f)
        # Combined = Diff + Gloss, as the library's (the compositor adds those two).
        planes["diffuse"][:] = planes["combined"]
        planes["diffuse_light"][:] = (0.5, 0.25 * f, 0.125)
        planes["alpha"] = np.ones((h, w), np.float32)
        return planes, {"seconds_total": 0.0, "skipped": ""}
    engine.RENDER_OVERRIDE = fake
