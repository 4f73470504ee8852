#!/usr/bin/env python3
"""dec_poisson.py -- the SciPy twin of bench/dec_poisson.c: the same DEC
Poisson pipeline (complex, circumcentric duals, Delta0, sparse factor,
solve) written the way a NumPy/SciPy user would, on the mesh file that
`dec_poisson gen` wrote.  Prints the same phase lines.

Triangles: edges by np.unique on sorted vertex pairs, boundary edges by
count, cotangent weights (*1 = (cot a + cot b)/2) and signed circumcentric
vertex areas, L = d0^T *1 d0 by sparse products, interior block by slicing,
scipy.sparse.linalg.splu (SuperLU) and its solve.
Tetrahedra: the circumcentric *1 of every edge from the signed flag sums
(edge midpoint, face circumcentre, tet circumcentre), vectorised.
"""
import resource
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def read(path):
    with open(path, "rb") as f:
        n, N, nv, nt = np.frombuffer(f.read(16), dtype=np.int32)
        X = np.frombuffer(f.read(8 * nv * N), dtype=np.float64).reshape(nv, N)
        T = np.frombuffer(f.read(4 * nt * (n + 1)), dtype=np.int32).reshape(nt, n + 1)
    return int(n), X, T


def faces(T, k):
    """Sorted k-faces of the simplices T, unique, and the simplex->face map."""
    n1 = T.shape[1]
    from itertools import combinations
    combos = list(combinations(range(n1), k + 1))
    F = np.sort(np.concatenate([T[:, c] for c in combos]), axis=1)
    U, inv = np.unique(F, axis=0, return_inverse=True)
    return U, inv.reshape(len(combos), -1).T, combos


def circumcentre(P):
    """Circumcentres of simplices P (m x (k+1) x N) and barycentrics."""
    E = P[:, 1:, :] - P[:, :1, :]
    G = np.einsum("mij,mkj->mik", E, E)
    a = np.linalg.solve(G, 0.5 * np.einsum("mii->mi", G)[..., None])[..., 0]
    b = np.concatenate([1 - a.sum(axis=1, keepdims=True), a], axis=1)
    return P[:, 0, :] + np.einsum("mi,mij->mj", a, E), b


def run(path):
    n, X, T = read(path)
    nv = X.shape[0]
    t0 = time.perf_counter()
    # complex: edges, d0, boundary vertices
    E, t2e, combos = faces(T, 1)
    ne = E.shape[0]
    rows = np.repeat(np.arange(ne), 2)
    d0 = sp.csr_matrix((np.tile([-1.0, 1.0], ne), (rows, E.ravel())), shape=(ne, nv))
    Fb, t2f, _ = faces(T, n - 1)
    cnt = np.bincount(t2f.ravel(), minlength=Fb.shape[0])
    bnd = np.zeros(nv, dtype=bool)
    bnd[Fb[cnt == 1].ravel()] = True
    t1 = time.perf_counter()
    # geometry: *1 and *0
    if n == 2:
        P = X[T]
        star1 = np.zeros(ne)
        area0 = np.zeros(nv)
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            u, v = P[:, j] - P[:, i], P[:, k] - P[:, i]
            cr = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
            cot = (u * v).sum(axis=1) / np.abs(cr)
            # edge (j, k) is opposite vertex i
            e_jk = t2e[:, combos.index(tuple(sorted((j, k))))]
            np.add.at(star1, e_jk, 0.5 * cot)
            l2 = ((P[:, k] - P[:, j]) ** 2).sum(axis=1)
            # the piece of *0 of j and k from edge (j,k): |e|^2 cot / 8 each
            np.add.at(area0, T[:, j], l2 * cot / 8)
            np.add.at(area0, T[:, k], l2 * cot / 8)
    else:
        P = X[T]
        cT, bT = circumcentre(P)
        star1 = np.zeros(ne)
        area0 = np.zeros(nv)
        for ei, (a, b) in enumerate(combos[:6] if False else [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]):
            e = t2e[:, combos.index((a, b))]
            mid = 0.5 * (P[:, a] + P[:, b])
            length = np.linalg.norm(P[:, b] - P[:, a], axis=1)
            piece = np.zeros(len(T))
            for c in set(range(4)) - {a, b}:
                fidx = [a, b, c]
                cf, bf = circumcentre(P[:, fidx])
                # signs: c's barycentric in the face, the opposite vertex's in the tet
                d = (set(range(4)) - set(fidx)).pop()
                s = np.sign(bf[:, 2]) * np.sign(bT[:, d])
                s[s == 0] = 1
                tri = np.cross(cf - mid, cT - mid)
                piece += s * 0.5 * np.linalg.norm(tri, axis=1)
            np.add.at(star1, e, piece / length)
        # no mass in 3-D (the C side solves S u = 1 too)
        area0[:] = 1.0
    t2 = time.perf_counter()
    L = (d0.T @ sp.diags(star1) @ d0).tocsr()
    inner = np.flatnonzero(~bnd)
    Lii = L[inner][:, inner].tocsc()
    t3 = time.perf_counter()
    lu = spla.splu(Lii)
    t4 = time.perf_counter()
    u = np.zeros(nv)
    u[inner] = lu.solve(area0[inner] * 1.0)
    t5 = time.perf_counter()
    centre = np.full(X.shape[1], 0.5 if n == 3 else 0.0)
    mid = np.argmin(((X - centre) ** 2).sum(axis=1))
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(f"complex {t1 - t0:.4f}\ngeometry {t2 - t1:.4f}\nassembly {t3 - t2:.4f}\n"
          f"factor {t4 - t3:.4f}\nsolve {t5 - t4:.4f}\ntotal {t5 - t0:.4f}")
    print(f"maxrss_kb {rss}\nunknowns {len(inner)}\nsimplices {len(T)}\ncheck {u[mid]:.10g}")


if __name__ == "__main__":
    run(sys.argv[1])
