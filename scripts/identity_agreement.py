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

from off_mesh import face_areas, read_off


def vertex_areas(pos, faces):
    w = [0.0] * len(pos)
    for (a, b, c), ar in zip(faces, face_areas(pos, faces)):
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
