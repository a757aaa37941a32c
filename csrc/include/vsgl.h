/**
 * @file vsgl.h
 * @brief Umbrella header of libvsgl: fast, deterministic one-bounce
 * glossy indirect light from virtual spherical Gaussian lights.
 *
 * Quick reference (each header documents units, frames, ownership):
 * - vsgl/base.h   result codes, version, ::vsgl_context
 * - vsgl/sg.h     spherical Gaussian operators
 * - vsgl/asg.h    anisotropic spherical Gaussian operators
 * - vsgl/lobes.h  BRDF lobes as SG/ASG, spherical warping
 * - vsgl/scene.h  scene input (triangles, materials, lights, camera)
 * - vsgl/render.h settings, outputs, ::vsgl_render
 * - vsgl/io.h     multilayer EXR writer, scene bundle files
 * - vsgl/debug.h, vsgl/reference.h  test entry points (G-buffer, RSM, brute force)
 */
#ifndef VSGL_H
#define VSGL_H
#include "vsgl/base.h"
#include "vsgl/sg.h"
#include "vsgl/asg.h"
#include "vsgl/lobes.h"
#include "vsgl/scene.h"
#include "vsgl/render.h"
#include "vsgl/io.h"
#endif
