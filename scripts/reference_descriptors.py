#!/usr/bin/env python3
"""Independent reference for coseg's HKS and WKS.

Recomputes the heat and wave kernel signatures with the formulas of pyFM
(github.com/RobinMagnet/pyFM, pyFM/signatures: HKS / WKS, written out here with numpy only)
from the SAME eigenpairs and the same time/energy grids that `coseg features --spectrum`
exported, and compares them with coseg's `descriptors.npy`, feature by feature:
Spearman rank correlation (what matters downstream) and the relative difference of values.

pyFM's `scaled=True` variants divide each feature by a per-scale constant; both are
compared (ranks are unaffected by that constant).

Usage:
    coseg features MESH -o DIR --spectrum
    python3 scripts/reference_descriptors.py DIR
Exit status 1 if any feature's Spearman correlation is below --min-spearman (default 0.999).
"""
import argparse
import json
import os
import sys

import numpy as np
from scipy.stats import spearmanr


def hks_pyfm(evals, evects, time_list, scaled):
    coefs = np.exp(-np.outer(time_list, evals))  # (T, K)
    natural = np.einsum("tk,nk->nt", coefs, np.square(evects))  # (N, T)
    if scaled:
        return natural / coefs.sum(1)[None, :]
    return natural


def wks_pyfm(evals, evects, energy_list, sigma, scaled):
    evals = np.asarray(evals).flatten()
    keep = np.where(evals > 1e-5)[0]
    evals = evals[keep]
    evects = evects[:, keep]
    e = np.asarray(energy_list)
    coefs = np.exp(-np.square(e[:, None] - np.log(np.abs(evals))[None, :]) / (2 * sigma**2))
    natural = np.einsum("tk,nk->nt", coefs, np.square(evects))
    if scaled:
        return natural / coefs.sum(1)[None, :]
    return natural


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--min-spearman", type=float, default=0.999)
    args = ap.parse_args()
    d = args.dir
    meta = json.load(open(os.path.join(d, "features.json")))
    evals = np.load(os.path.join(d, "eigenvalues.npy"))
    evects = np.load(os.path.join(d, "eigenvectors.npy"))
    areas = np.load(os.path.join(d, "vertex_areas.npy"))
    ours = np.load(os.path.join(d, "descriptors.npy"))
    # Sanity: the exported basis is M-orthonormal for the unit-area mass.
    gram = evects.T @ (areas[:, None] * evects)
    print(f"mesh: {evects.shape[0]} vertices, {evects.shape[1]} eigenpairs, "
          f"|Phi^T M Phi - I|_max = {np.abs(gram - np.eye(gram.shape[0])).max():.2e}, "
          f"sum(area) = {areas.sum():.12f}")
    t = np.asarray(meta["hks_times"])
    e = np.asarray(meta["wks_energies"])
    sigma = meta["wks_sigma"]
    nh, nw = len(t), len(e)
    # coseg's HKS is pyFM's unscaled HKS; coseg's WKS is pyFM's scaled (normalised) WKS.
    blocks = {
        "HKS": (ours[:, :nh], hks_pyfm, (t,), False),
        "WKS": (ours[:, nh:nh + nw], wks_pyfm, (e, sigma), True),
    }
    worst = 1.0
    for name, (mine, fn, extra, same) in blocks.items():
        for scaled in (False, True):
            ref = fn(evals, evects, *extra, scaled=scaled)
            rho = np.array([spearmanr(mine[:, j], ref[:, j]).statistic for j in range(mine.shape[1])])
            worst = min(worst, rho.min())
            msg = (f"{name} (pyFM scaled={scaled}): {mine.shape[1]} features, Spearman min {rho.min():.9f} "
                   f"(1 - min = {1 - rho.min():.1e}), median {np.median(rho):.9f}")
            if scaled == same:
                rel = np.abs(mine - ref).max(0) / np.abs(ref).max(0)
                msg += f", max relative value difference {rel.max():.2e}"
            print(msg)
    print(f"worst Spearman correlation: {worst:.9f} (threshold {args.min_spearman})")
    sys.exit(0 if worst >= args.min_spearman else 1)


if __name__ == "__main__":
    main()
