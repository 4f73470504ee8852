#!/usr/bin/python3
"""Independent reference values for the connection tests (tests/c/test_conn_*.c,
tests/lua/conn_*.lua), computed with NumPy/SciPy from the closed forms of
doc/bundles-connections-holonomy.md, without dmech.
Run: /usr/bin/python3 tests/data/conn/reference.py
"""
import numpy as np
from scipy.integrate import quad
from scipy.linalg import expm, logm

pi = np.pi

def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])

def vee(M):
    return np.array([M[2, 1], M[0, 2], M[1, 0]])

def so3log(R):
    return vee(np.real(logm(R)))

# ---- platform: A = m(-v, u)/(I + m rho^2), I = m = 1 ----------------------
def A_plat(x, I=1.0, m=1.0):
    u, v = x
    D = I + m * (u * u + v * v)
    return np.array([-m * v / D, m * u / D])

def f(r, I=1.0, m=1.0):
    return m * r * r / (I + m * r * r)

print("phase exact phase -0.15 pi =", -0.15 * pi, " check", -(f(2) - f(1)) * pi / 2)

def sector_polygon(N):
    pts = []
    for k in range(N):                       # r: 1 -> 2 at phi = 0
        pts.append((1 + k / N, 0.0))
    for k in range(N):                       # arc r = 2, phi: 0 -> pi/2
        p = (pi / 2) * k / N
        pts.append((2 * np.cos(p), 2 * np.sin(p)))
    for k in range(N):                       # r: 2 -> 1 at phi = pi/2
        r = 2 - k / N
        pts.append((0.0, r))
    for k in range(N):                       # arc r = 1 back, phi: pi/2 -> 0
        p = (pi / 2) * (1 - k / N)
        pts.append((np.cos(p), np.sin(p)))
    pts.append(pts[0])
    return np.array(pts)

def abelian_holo(A, pts, rule):
    s = 0.0
    for a, b in zip(pts[:-1], pts[1:]):
        x = a if rule == "euler" else 0.5 * (a + b)
        s -= A(x) @ (b - a)
    return s

for N in (8, 16, 32):
    print("phase midpoint N=%d error %.6e" % (N, abelian_holo(A_plat, sector_polygon(N), "midpoint") + 0.15 * pi))

# continuous transport around the sector: -int A.dx along the four pieces
def line_int(A, path, dpath):
    return quad(lambda s: -A(path(s)) @ dpath(s), 0, 1, epsabs=1e-14, epsrel=1e-14, limit=200)[0]

cc3 = (line_int(A_plat, lambda s: np.array([1 + s, 0]), lambda s: np.array([1, 0]))
       + line_int(A_plat, lambda s: 2 * np.array([np.cos(pi / 2 * s), np.sin(pi / 2 * s)]),
                  lambda s: pi * np.array([-np.sin(pi / 2 * s), np.cos(pi / 2 * s)]))
       + line_int(A_plat, lambda s: np.array([0, 2 - s]), lambda s: np.array([0, -1]))
       + line_int(A_plat, lambda s: np.array([np.cos(pi / 2 * (1 - s)), np.sin(pi / 2 * (1 - s))]),
                  lambda s: -pi / 2 * np.array([-np.sin(pi / 2 * (1 - s)), np.cos(pi / 2 * (1 - s))])))
print("continuous continuous transport %.15f" % cc3)

# ---- order defects of the platform connection ------------------------
x0 = np.array([1.0, 0.5]); v = np.array([0.6, 0.8])
def transport_angle(x0, x1):
    return quad(lambda s: -A_plat(x0 + s * (x1 - x0)) @ (x1 - x0), 0, 1, epsabs=1e-15, epsrel=1e-15)[0]
for rule in ("euler", "midpoint"):
    ds = []
    for h in (0.2, 0.1, 0.05, 0.025):
        x1 = x0 + h * v
        ref = -transport_angle(x0, x1)        # A = H^-1
        xx = x0 if rule == "euler" else 0.5 * (x0 + x1)
        ds.append(abs(A_plat(xx) @ (x1 - x0) - ref))
    print("discrete %s defects" % rule, " ".join("%.3e" % d for d in ds))
ds = []
for h in (0.2, 0.1, 0.05, 0.025):
    x1 = x0 + h * v
    ref = -transport_angle(x0, x1)
    w = A_plat(0.5 * (x0 + x1)) @ (x1 - x0)
    ds.append(abs(2 * np.arctan(w / 2) - ref))
print("discrete cayley defects", " ".join("%.3e" % d for d in ds))

# ---- three-link planar cat --------------------------------------------------
def cat_r(x):
    x1, x2 = x
    c = [np.array([0.0, 0.0]),
         np.array([-0.5 - 0.5 * np.cos(x1), -0.5 * np.sin(x1)]),
         np.array([0.5 + 0.5 * np.cos(x2), 0.5 * np.sin(x2)])]
    cm = sum(c) / 3
    return [ci - cm for ci in c]

def A_cat(x, h=1e-6):
    r = cat_r(x)
    num = np.array([1 / 12, 1 / 12])
    for k in range(2):
        e = np.zeros(2); e[k] = h
        rp, rm = cat_r(x + e), cat_r(x - e)
        for i in range(3):
            dr = (rp[i] - rm[i]) / (2 * h)
            num[k] += r[i][0] * dr[1] - r[i][1] * dr[0]
    den = sum(ri @ ri for ri in r) + 3 / 12
    return num / den

print("phase A_cat(0,0) =", A_cat(np.array([0.0, 0.0])), " 7/27 =", 7 / 27)
def circle(c, R, N):
    t = np.linspace(0, 2 * pi, N + 1)
    pts = np.stack([c[0] + R * np.cos(t), c[1] + R * np.sin(t)], axis=1)
    pts[-1] = pts[0]
    return pts
def circle_exact(c, R):
    return quad(lambda t: -A_cat(np.array([c[0] + R * np.cos(t), c[1] + R * np.sin(t)]))
                @ (R * np.array([-np.sin(t), np.cos(t)])), 0, 2 * pi, epsabs=1e-13, epsrel=1e-13, limit=400)[0]
ex = circle_exact((1, 0.5), 0.5)
print("phase circle r=0.5 about (1, 0.5): %.10f" % ex)
for rule in ("euler", "midpoint"):
    print("phase %s errors" % rule, " ".join("%.4e" % (abelian_holo(A_cat, circle((1, 0.5), 0.5, N), rule) - ex) for N in (8, 16, 32)))
print("phase circle r=1 about (1, -1): %.10f" % circle_exact((1, -1), 1.0))

# ---- rotor craft --------------------------------------------------------------
u1 = np.array([0.1, 0, 0]); u2 = np.array([0, 0.2, 0])
for a in (1.0,):
    P = expm(-a * hat(u1)) @ expm(-a * hat(u2)) @ expm(a * hat(u1)) @ expm(a * hat(u2))
    print("continuous log P at a=b=1:", " ".join("%.12g" % c for c in so3log(P)))
for a in (1e-1, 1e-2):
    P = expm(-a * hat(u1)) @ expm(-a * hat(u2)) @ expm(a * hat(u1)) @ expm(a * hat(u2))
    print("continuous log P/(ab) at a=b=%g:" % a, so3log(P) / a ** 2)

# ---- sphere: Foucault --------------------------------------------------------
def sph_rot(p0, p1):
    a = np.cross(p0, p1); c = p0 @ p1
    return c * np.eye(3) + hat(a) + np.outer(a, a) / (1 + c)
def geo_holo(pts):
    R = np.eye(3)
    for p0, p1 in zip(pts[:-1], pts[1:]):
        R = sph_rot(p0, p1) @ R
    M = R           # R0 = I: R_N = M R0, angle of R0^T R_N about e3
    return np.arctan2(M[1, 0], M[0, 0])
print("phase octant:", geo_holo([np.array(p, float) for p in ((0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1))]), pi / 2)
lat = pi / 6
for N in (16, 64, 256):
    # start on the latitude circle, frame R0 with R0 e3 = p0
    th = np.linspace(0, 2 * pi, N + 1)
    pts = [np.array([np.cos(lat) * np.cos(t), np.cos(lat) * np.sin(t), np.sin(lat)]) for t in th]
    pts[-1] = pts[0]
    p0 = pts[0]
    e1 = np.array([0, 1.0, 0]); e2 = np.cross(p0, e1)
    R0 = np.stack([e1, e2, p0], axis=1)
    R = R0
    for a, b in zip(pts[:-1], pts[1:]):
        R = sph_rot(a, b) @ R
    M = R0.T @ R
    ang = np.arctan2(M[1, 0], M[0, 0]) % (2 * pi)
    print("phase Foucault lat 30, N=%d: %.6f" % (N, ang))

# ---- rigid-body phase --------------------------------------------------------
beta = 0.6
T = 4 * pi / np.cos(beta)
print("phase T = %.7f, T mod 2pi = %.7f, -Lambda + 2HT mod 2pi = %.7f" %
      (T, T % (2 * pi), (-2 * pi * (1 - np.cos(beta)) + 2 * 0.5 * (np.sin(beta) ** 2 + np.cos(beta) ** 2 / 2) * T) % (2 * pi)))

# ---- Heisenberg hexagon --------------------------------------------------------
N = 6
print("mechanical hexagon -(N/2) sin(2pi/N) = %.7f" % (-(N / 2) * np.sin(2 * pi / N)))

# ---- the exact rule violates fibre compatibility ------------------------------------------------
w = np.array([0.15, 0.2, -0.06])
g0 = expm(hat([0.4, -0.3, 0.8])); g1 = expm(hat([0.5, -0.1, 0.9])); hh = expm(hat([0.2, 0.7, -0.4]))
def AE(g0, g1):
    eta = so3log(g1 @ g0.T)
    return expm(hat(eta + g0 @ w))
print("fibre-compatibility defect of exact: %.4f" % np.linalg.norm(so3log(AE(g0, hh @ g1) @ np.linalg.inv(hh @ AE(g0, g1)))))
