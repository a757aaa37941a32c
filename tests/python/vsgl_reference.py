"""Independent double-precision references for the libvsgl binding tests.

Nothing here calls the library: quadrature rules on the sphere (graded
Gauss-Legendre panels concentrated where a lobe lives) and numpy
re-implementations of the formulas the headers document.
"""

import math

import numpy as np

_GL_CACHE = {}


def gauss_legendre(n):
    if n not in _GL_CACHE:
        _GL_CACHE[n] = np.polynomial.legendre.leggauss(n)
    return _GL_CACHE[n]


def graded_rule(a, b, centres=(), n=24, growth=2.0):
    """Gauss-Legendre nodes/weights on [a, b], with panel breaks at
    c +/- w * growth**k for each (c, w) in ``centres`` (a lobe of width w
    at c is resolved however small w is)."""
    breaks = {float(a), float(b)}
    for c, w in centres:
        w = max(float(w), 1e-300)
        for sign in (-1.0, 1.0):
            k = 0
            while True:
                x = c + sign * w * growth ** k
                if x <= a or x >= b:
                    break
                breaks.add(float(x))
                k += 1
        if a < c < b:
            breaks.add(float(c))
    br = np.array(sorted(breaks))
    br = br[np.concatenate([[True], np.diff(br) > 1e-300])]
    xg, wg = gauss_legendre(n)
    lo, hi = br[:-1], br[1:]
    half = 0.5 * (hi - lo)
    mid = 0.5 * (hi + lo)
    x = (mid[:, None] + half[:, None] * xg[None, :]).ravel()
    w = (half[:, None] * wg[None, :]).ravel()
    return x, w


def frame_from_z(z):
    """Right-handed orthonormal rows x, y, z with z given."""
    z = np.asarray(z, float) / np.linalg.norm(z)
    a = np.array([1.0, 0, 0]) if abs(z[0]) < 0.9 else np.array([0, 1.0, 0])
    x = np.cross(a, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.array([x, y, z])


def axis_rule(axis, width, n_phi=64, n=24):
    """Directions and weights for the whole sphere in polar coordinates
    about ``axis``: u = 1 - cos(theta) in [0, 2] graded near 0 with
    ``width`` (1/sharpness for an SG about ``axis``), phi uniform."""
    u, wu = graded_rule(0.0, 2.0, [(0.0, width)], n)
    phi = (np.arange(n_phi) + 0.5) * (2 * np.pi / n_phi)
    F = frame_from_z(axis)
    cz = 1.0 - u
    sz = np.sqrt(np.clip(u * (2.0 - u), 0.0, None))
    d = (sz[:, None, None] * (np.cos(phi)[None, :, None] * F[0] + np.sin(phi)[None, :, None] * F[1])
         + cz[:, None, None] * F[2])
    w = wu[:, None] * np.full(n_phi, 2 * np.pi / n_phi)[None, :]
    return d.reshape(-1, 3), w.ravel()


def disk_rule(frame, centres_x=(), centres_y=(), n=24):
    """Rule for integrals of the form  int max(v.z, 0) h(v) dv  over the
    sphere, i.e. the double integral of h over the unit disk of (v.x, v.y):
    v.x = sin t, v.y = cos t sin r, v.z = cos t cos r, weights
    cos^2 t cos r dt dr (every coordinate smooth up to the rim).
    ``centres_x`` are (t, width) pairs, ``centres_y`` (r, width).
    Returns (dirs (N,3), weights (N,)) with sum(w * h(dirs)) ~ the integral."""
    F = np.asarray(frame, float)
    t, wt = graded_rule(-np.pi / 2, np.pi / 2, list(centres_x) + [(0.0, 1.0)], n)
    r, wr = graded_rule(-np.pi / 2, np.pi / 2, list(centres_y) + [(0.0, 1.0)], n)
    ct = np.cos(t)
    vx = np.sin(t)[:, None] * np.ones_like(r)[None, :]
    vy = ct[:, None] * np.sin(r)[None, :]
    vz = ct[:, None] * np.cos(r)[None, :]
    d = vx[..., None] * F[0] + vy[..., None] * F[1] + vz[..., None] * F[2]
    w = (wt * ct * ct)[:, None] * (wr * np.cos(r))[None, :]
    return d.reshape(-1, 3), w.ravel()


def disk_centres(frame, direction, width):
    """Grading centres in disk_rule coordinates for a lobe at ``direction``
    (projected into the upper hemisphere) of angular ``width``."""
    F = np.asarray(frame, float)
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    px, py, pz = F @ d
    cx, cy = [], []
    pts = [(px, py)]
    if pz < 0.5:  # near or below the horizon: also the nearest rim point
        r = math.hypot(px, py)
        if r > 0:
            pts.append((px / r, py / r))
    for x, y in pts:
        x = min(max(x, -1.0), 1.0)
        t = math.asin(x)
        ct = math.cos(t)
        s = min(max(y / ct, -1.0), 1.0) if ct > 1e-300 else 0.0
        r = math.asin(s)
        w = max(width, 1e-12)
        cx += [(t, w)]
        cy += [(r, w)]
    return cx, cy


def integrate_log(logf, dirs, w):
    """sum(w * exp(logf(dirs))) computed without underflow: (value, log scale)."""
    L = logf(dirs)
    m = np.max(L)
    if not np.isfinite(m):
        return 0.0
    return float(np.exp(m) * np.sum(w * np.exp(L - m)))


# ---------------------------------------------------------------------------
# Lobes as numpy functions (log-domain), straight from the header formulas
# ---------------------------------------------------------------------------


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def f32(x):
    """Round to float32 and back (the values the library actually receives)."""
    return np.float64(np.float32(x))


def sg_log(axis, sharpness, log_amp):
    xi = unit(axis)
    return lambda d: log_amp + sharpness * (unit_rows(d) @ xi - 1.0)


def unit_rows(d):
    d = np.asarray(d, float)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def asg_log_smooth(x, y, lam, mu, log_amp):
    """log of c * exp(-lam (v.x)^2 - mu (v.y)^2) (the max(v.z,0) factor left out)."""
    x, y = np.asarray(x, float), np.asarray(y, float)

    def f(d):
        d = unit_rows(d)
        return log_amp - lam * (d @ x) ** 2 - mu * (d @ y) ** 2
    return f


def asg_value(x, y, z, lam, mu, log_amp, d):
    d = unit_rows(d)
    return (np.exp(log_amp) * np.maximum(d @ np.asarray(z, float), 0.0)
            * np.exp(-lam * (d @ np.asarray(x, float)) ** 2 - mu * (d @ np.asarray(y, float)) ** 2))


def sg_area(lam):
    """A(lam) = 2 pi (1 - exp(-2 lam)) / lam in double (4 pi at 0)."""
    lam = float(lam)
    if lam == 0.0:
        return 4 * np.pi
    return -2 * np.pi * math.expm1(-2 * lam) / lam


def quad_sg_integral(lam):
    """Quadrature of exp(lam (w.xi - 1)) over the sphere (independent of sg_area)."""
    u, wu = graded_rule(0.0, 2.0, [(0.0, 1.0 / max(lam, 1e-300))], 24)
    return float(2 * np.pi * np.sum(wu * np.exp(-lam * u)))


def quad_sg_product(a, b):
    """Quadrature of G_a * G_b; a, b = (axis, sharpness, log_amp) in double."""
    (x1, l1, c1), (x2, l2, c2) = a, b
    s = l1 * unit(x1) + l2 * unit(x2)
    lm = np.linalg.norm(s)
    axis = s / lm if lm > 1e-12 * max(l1 + l2, 1e-300) else unit(x1)
    dirs, w = axis_rule(axis, 1.0 / max(lm, 1e-6), n_phi=48, n=24)
    f1, f2 = sg_log(x1, l1, c1), sg_log(x2, l2, c2)
    return integrate_log(lambda d: f1(d) + f2(d), dirs, w)


def quad_sg_clamped_cosine(axis, lam, log_amp, n, n_nodes=24):
    """Quadrature of G(w) max(w.n, 0) (disk rule about n, graded at the lobe)."""
    F = frame_from_z(n)
    cx, cy = disk_centres(F, axis, 1.0 / math.sqrt(max(lam, 1e-12)))
    dirs, w = disk_rule(F, cx, cy, n_nodes)
    return integrate_log(sg_log(axis, lam, log_amp), dirs, w)


def quad_asg_times(asg, other_log=None, other_dir=None, other_width=None, n=24):
    """Quadrature of ASG(v) * exp(other_log(v)) (or of the ASG alone)."""
    x, y, z, lam, mu, la = asg
    F = np.array([unit(x), unit(y), unit(z)])
    cx = [(0.0, 1.0 / math.sqrt(max(lam, 1e-12)))]
    cy = [(0.0, 1.0 / math.sqrt(max(mu, 1e-12)))]
    if other_dir is not None:
        ox, oy = disk_centres(F, other_dir, other_width)
        cx += ox
        cy += oy
    dirs, w = disk_rule(F, cx, cy, n)
    base = asg_log_smooth(F[0], F[1], lam, mu, la)
    if other_log is None:
        return integrate_log(base, dirs, w)
    # locate the product's peak and grade there as well
    L = base(dirs) + other_log(dirs)
    peak = dirs[int(np.argmax(L))]
    width = min(1.0 / math.sqrt(max(lam, mu, 1e-12)), other_width or 1.0)
    px, py = disk_centres(F, peak, width)
    dirs, w = disk_rule(F, cx + px, cy + py, n)
    return integrate_log(lambda d: base(d) + other_log(d), dirs, w)


def bessel_f_quad(a):
    """F(a) = int_0^{2pi} exp(-a cos^2 phi) dphi by graded Gauss-Legendre."""
    width = 1.0 / math.sqrt(max(a, 1e-12))
    p, wp = graded_rule(0.0, np.pi, [(np.pi / 2, width)], 24)
    return float(2.0 * np.sum(wp * np.exp(-a * np.cos(p) ** 2)))


def rand_frame(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 2] = -q[:, 2]
    return q.T  # rows x, y, z; right-handed


def asg_log(t, d):
    """log of the ASG t at unit rows d (-inf below the horizon)."""
    x, y, z, lam, mu, la = t
    d = unit_rows(d)
    with np.errstate(divide="ignore"):
        return la + np.log(np.maximum(d @ z, 0.0)) - lam * (d @ x) ** 2 - mu * (d @ y) ** 2


def dirs_near(z, width, rng, count):
    F = frame_from_z(z)
    t = np.abs(rng.normal(size=count)) * width
    t = np.minimum(t, 1.4)
    ph = rng.uniform(0, 2 * np.pi, count)
    return (np.sin(t)[:, None] * (np.cos(ph)[:, None] * F[0] + np.sin(ph)[:, None] * F[1])
            + np.cos(t)[:, None] * F[2])
