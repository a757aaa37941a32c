"""The lattice fit holds still: it does not depend on the camera, and a
light that moves a little changes the AOV a little, without jitter (issue 9).
The importance-drawn fits are the contrast that shows the checks can fail."""
import numpy as np

import libvsgl as L
import scenes


def _scene(ctx, light_x=0.0, cam_x=0.0, w=40, h=30):
    d = scenes.floor_and_wall(wall=True, width=w, height=h)
    T = np.eye(4)
    T[:3, 3] = (light_x, 0.0, 2.5)
    d["lights"] = [L.Light(type="spot", color=(1, 1, 1), power=500.0, world_from_light=T,
                           spot_size=1.2, spot_blend=0.1, radius=0.05)]
    d["camera"] = L.Camera(type="perspective", sensor_fit="auto",
                           world_from_camera=scenes.blender_camera_matrix((cam_x, -6, 1.5)),
                           lens_mm=35, sensor_width_mm=36, sensor_height_mm=24, clip_start=0.1,
                           clip_end=100, width=w, height=h, pixel_aspect_x=1, pixel_aspect_y=1)
    return L.Scene(ctx, **d)


def _settings(fit):
    s = L.render_settings_preset(L.Preset.BALANCED)
    s.fit_mode = fit
    s.aa_samples = 1
    return s


def test_lattice_fit_does_not_depend_on_the_camera():
    with L.Context() as ctx:
        a = L.debug_vsgls(ctx, _scene(ctx, cam_x=0.0), _settings(L.FitMode.LATTICE))
        b = L.debug_vsgls(ctx, _scene(ctx, cam_x=0.37), _settings(L.FitMode.LATTICE))
    assert len(a["power"]) > 16
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def _flicker(fit, steps=8, step=0.002):
    """Median relative RMS of consecutive frames and of second differences, light moving `step` m a frame."""
    with L.Context() as ctx:
        frames = []
        for i in range(steps):
            img, _ = L.render(ctx, _scene(ctx, light_x=step * i), _settings(fit), planes=("combined",))
            frames.append(img["combined"].astype(np.float64))
    f = np.array(frames)
    d1 = np.sqrt(((f[1:] - f[:-1]) ** 2).sum(axis=(1, 2, 3)) / (f[:-1] ** 2).sum(axis=(1, 2, 3)))
    d2 = np.sqrt(((f[2:] - 2 * f[1:-1] + f[:-2]) ** 2).sum(axis=(1, 2, 3)) / (f[1:-1] ** 2).sum(axis=(1, 2, 3)))
    return float(np.median(d1)), float(np.median(d2))


def test_lattice_light_motion_is_smooth_and_importance_fits_are_not():
    first, second = _flicker(L.FitMode.LATTICE)
    # a 2 mm step in a 4 m room: the light itself changes by well under 1 %
    assert first < 0.01, first
    # smooth motion: second differences far below first differences (measured 0.0085x; jitter makes
    # them comparable or larger; 0.034x while negligible specular VSGLs were dropped without a fade)
    assert second < 0.02 * first, (first, second)
    # k-means centres drawn from the light's power reshuffle: the same check fails for it (0.06x here)
    km_first, km_second = _flicker(L.FitMode.KMEANS)
    assert km_second > 0.02 * km_first, (km_first, km_second)


def _tilted_floor(ctx, deg):
    """scenes.floor_and_wall with its floor tilted by `deg` about y (the wall
    lit by it sees the light the floor reflects)."""
    d = scenes.floor_and_wall(wall=True, width=40, height=30)
    d["positions"] = d["positions"].copy()
    d["positions"][:4, 2] = d["positions"][:4, 0] * np.tan(np.radians(deg))
    return L.Scene(ctx, **d)


def test_lattice_keeps_a_slightly_tilted_floor_in_one_orientation_bin():
    """A floor 8 deg off the horizontal is fitted with as many clusters as a
    flat one: with orientation weights n_a^2 and no dead zone its 2 % along
    x filled a second bin at the full lattice density (about twice the
    floor's VSGLs, each of the second bin's with ~1/50 of the light)."""
    counts = {}
    with L.Context() as ctx:
        for deg in (0.0, 8.0, 30.0):
            v = L.debug_vsgls(ctx, _tilted_floor(ctx, deg), _settings(L.FitMode.LATTICE))
            counts[deg] = int((v["normal"][:, 2] > 0.5).sum())  # the floor's
    assert counts[0.0] > 16
    assert counts[8.0] <= 1.2 * counts[0.0], counts
    # past the dead zone the second bin takes its share: the count grows
    assert counts[30.0] > 1.5 * counts[0.0], counts
