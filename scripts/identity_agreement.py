#!/usr/bin/env python3
"""Agreement of region ids under the identity map, from a `coseg segment` output folder.

For shapes that share their triangulation (vertex i of one is vertex i of the others: a TOSCA
class, FAUST), the mean over all pairs of shapes of the area share where both give a vertex the
same region id (area = the mean of the two shapes' barycentric vertex areas), as
examples/eval_collection.rs measures it; also the worst pair and the number of region ids.
usage: identity_agreement.py OUT_DIR MESH...   (MESH: the .off files given to coseg segment)
Pure Python, deterministic.
"""
import os, sys


def read_off(path):
    with open(path) as f:
        toks = f.read().split()
    i = 1 if toks[0].upper() == "OFF" else 0
    nv, nf = int(toks[i]), int(toks[i + 1])
    i += 3
    pos = [tuple(map(float, toks[i + 3 * k:i + 3 * k + 3])) for k in range(nv)]
    i += 3 * nv
    faces = []
    for _ in range(nf):
        n = int(toks[i])
        faces.append(tuple(int(t) for t in toks[i + 1:i + 1 + n])[:3])
        i += 1 + n
    return pos, faces


def vertex_areas(pos, faces):
    w = [0.0] * len(pos)
    for a, b, c in faces:
        pa, pb, pc = pos[a], pos[b], pos[c]
        u = [pb[k] - pa[k] for k in range(3)]
        v = [pc[k] - pa[k] for k in range(3)]
        x = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        ar = 0.5 * (x[0] ** 2 + x[1] ** 2 + x[2] ** 2) ** 0.5
        for i in (a, b, c):
            w[i] += ar / 3.0
    t = sum(w)
    return [x / t for x in w]


def main(out, meshes):
    labels, areas = [], []
    for m in meshes:
        stem = os.path.splitext(os.path.basename(m))[0]
        labels.append([int(l) for l in open(os.path.join(out, stem + ".regions.txt")) if l.strip()])
        pos, faces = read_off(m)
        areas.append(vertex_areas(pos, faces))
    n = len(labels)
    total, worst, count = 0.0, 1.0, 0
    for i in range(n):
        for j in range(i + 1, n):
            li, lj, ai, aj = labels[i], labels[j], areas[i], areas[j]
            agree = sum(0.5 * (ai[v] + aj[v]) for v in range(len(li)) if li[v] == lj[v])
            tot = sum(0.5 * (ai[v] + aj[v]) for v in range(len(li)))
            f = agree / tot
            total += f
            worst = min(worst, f)
            count += 1
    ids = len(set(x for l in labels for x in l))
    print(f"agreement {100 * total / count:.2f} % (worst pair {100 * worst:.2f} %), {ids} region ids, {n} shapes")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
