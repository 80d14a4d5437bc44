#!/usr/bin/env python3
"""Reference spectrum with SciPy, for comparison with `coseg spectrum`.

Reads an OFF mesh, builds the same cotangent Laplacian L (weak form, PSD) and barycentric lumped
mass M as coseg (mesh scaled to unit total area: M / area; L is scale invariant), and times
scipy.sparse.linalg.eigsh(L, k, M=M, sigma=SIGMA, which='LM') (shift-invert mode, SuperLU).

Usage: scripts/scipy_spectrum.py MESH.off [-k 200] [--sigma -0.01] [--repeat 1] [--json]
Prints the wall-clock seconds of eigsh (build time separately) and the first eigenvalues.
"""
import argparse
import json
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla


def read_off(path):
    with open(path) as f:
        tokens = []
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                tokens.append(line)
    header = tokens[0]
    if not header.endswith("OFF"):
        raise SystemExit(f"{path}: not an OFF file")
    rest = tokens[1:]
    if header != "OFF" and len(header.split()) > 1:
        rest = [header[len("OFF"):]] + rest
    nv, nf = map(int, rest[0].split()[:2])
    pos = np.array([list(map(float, l.split()[:3])) for l in rest[1:1 + nv]])
    faces = []
    for l in rest[1 + nv:1 + nv + nf]:
        idx = list(map(int, l.split()))
        n = idx[0]
        poly = idx[1:1 + n]
        for i in range(1, n - 1):
            faces.append([poly[0], poly[i], poly[i + 1]])
    return pos, np.array(faces, dtype=np.int64)


def cotan_laplacian_and_mass(pos, faces):
    d = len(pos)
    p = [pos[faces[:, i]] for i in range(3)]
    i_idx, j_idx, vals = [], [], []
    area = 0.5 * np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]), axis=1)
    cots = []
    for k in range(3):
        u = p[(k + 1) % 3] - p[k]
        v = p[(k + 2) % 3] - p[k]
        c = np.linalg.norm(np.cross(u, v), axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            cots.append(np.einsum("ij,ij->i", u, v) / c)
    cots = np.stack(cots, axis=1)
    ok = np.all(np.isfinite(cots), axis=1) & (area > 0)
    big = np.abs(cots).max(axis=1)
    scale = np.where(big > 1e5, 1e5 / np.maximum(big, 1e-300), 1.0)
    cots = cots * scale[:, None]
    cots[~ok] = 0.0
    for k in range(3):
        a = faces[:, (k + 1) % 3]
        b = faces[:, (k + 2) % 3]
        w = 0.5 * cots[:, k]
        i_idx += [a, b, a, b]
        j_idx += [b, a, a, b]
        vals += [-w, -w, w, w]
    L = sp.csc_matrix(
        (np.concatenate(vals), (np.concatenate(i_idx), np.concatenate(j_idx))), shape=(d, d)
    )
    mass = np.zeros(d)
    for k in range(3):
        np.add.at(mass, faces[:, k], area / 3.0)
    total = area.sum()
    return L, sp.diags(mass / total).tocsc()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh")
    ap.add_argument("-k", type=int, default=200)
    ap.add_argument("--sigma", type=float, default=-0.01)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    t0 = time.perf_counter()
    pos, faces = read_off(args.mesh)
    L, M = cotan_laplacian_and_mass(pos, faces)
    build = time.perf_counter() - t0
    try:
        # The BLAS SciPy runs on, as its users get it: no thread or core-type overrides.
        from threadpoolctl import threadpool_info

        blas = [
            f"{i['internal_api']} {i.get('version')} {i.get('architecture')} "
            f"threads={i['num_threads']}"
            for i in threadpool_info()
        ]
    except ImportError:
        blas = ["threadpoolctl not installed"]
    times = []
    vals = None
    for _ in range(args.repeat):
        t = time.perf_counter()
        vals, vecs = sla.eigsh(L, k=args.k, M=M, sigma=args.sigma, which="LM")
        times.append(time.perf_counter() - t)
    vals = np.sort(vals)
    out = {
        "mesh": args.mesh,
        "vertices": len(pos),
        "k": args.k,
        "sigma": args.sigma,
        "build_seconds": build,
        "blas": blas,
        "eigsh_seconds": times,
        "eigenvalues": vals.tolist(),
    }
    if args.json:
        print(json.dumps(out))
    else:
        print(f"{args.mesh}: {len(pos)} vertices, k={args.k}, sigma={args.sigma}")
        print("blas:", "; ".join(blas))
        print(f"build {build:.3f} s, eigsh {' '.join(f'{t:.3f}' for t in times)} s")
        print("first eigenvalues:", " ".join(f"{v:.9e}" for v in vals[:8]))
        print("last eigenvalue:", f"{vals[-1]:.9e}")


if __name__ == "__main__":
    sys.exit(main())
