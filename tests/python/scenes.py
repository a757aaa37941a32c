"""Tiny test scenes as the numpy arrays/structs the binding takes."""

import numpy as np

import libvsgl as L


def blender_camera_matrix(location, rot_x_deg=90.0):
    """world_from_camera of a camera rotated about X (90 deg looks along +Y)."""
    a = np.radians(rot_x_deg)
    M = np.eye(4)
    M[:3, :3] = [[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]]
    M[:3, 3] = location
    return M


def camera(width=16, height=12):
    return L.Camera(type="perspective", sensor_fit="auto",
                    world_from_camera=blender_camera_matrix((0, -6, 1.5)),
                    lens_mm=35, sensor_width_mm=36, sensor_height_mm=24, clip_start=0.1,
                    clip_end=100, width=width, height=height, pixel_aspect_x=1, pixel_aspect_y=1)


def spot_light(power=500.0, height=2.5):
    T = np.eye(4)
    T[:3, 3] = (0, 0, height)
    return L.Light(type="spot", color=(1, 1, 1), power=power, world_from_light=T,
                   spot_size=1.2, spot_blend=0.1, radius=0.05)


def floor_and_wall(wall=True, width=16, height=12):
    """A 4 x 4 m grey floor at z = 0 (and a wall at y = 2), a spot above."""
    P = np.array([[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0],
                  [-2, 2, 0], [2, 2, 0], [2, 2, 3], [-2, 2, 3]], np.float32)
    I = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]], np.uint32)
    if not wall:
        P, I = P[:4].copy(), I[:2].copy()
    return dict(positions=P, indices=I,
                materials=[L.Material(base_color=(0.8, 0.8, 0.8), roughness=0.5,
                                      specular_f0=0.04)],
                lights=[spot_light()], camera=camera(width, height))
