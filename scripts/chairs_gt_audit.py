#!/usr/bin/env python3
"""Audit of the COSEG chairs ground truth (no numpy needed).

    python3 scripts/chairs_gt_audit.py ../shared/data/coseg_chairs

Per chair: the area share and the mean height (y, the set's up axis) and depth (z) of every
label's faces, which part each label is by its position (highest = back, lowest = legs), and
the best one-source accuracy a perfect method could reach when scored against the files as
they are and against labels made consistent (1 <-> 3 exchanged on the chairs whose label 1 is
lowest). Docs: docs/PROPAGATION.md ("The ground truth").
"""
import os
import sys


def read(folder, n):
    words = open(os.path.join(folder, "shapes", f"{n}.off")).read().split()
    nv, nf = int(words[1]), int(words[2])
    v = [tuple(map(float, words[4 + 3 * i:7 + 3 * i])) for i in range(nv)]
    o = 4 + 3 * nv
    faces = [tuple(int(x) for x in words[o + 4 * f + 1:o + 4 * f + 4]) for f in range(nf)]
    gt = [int(x) for x in open(os.path.join(folder, "gt", f"{n}.seg")).read().split()]
    return v, faces, gt


def main(folder):
    names = sorted((f[:-4] for f in os.listdir(os.path.join(folder, "shapes"))), key=int)
    shares, swapped = {}, set()
    for n in names:
        v, faces, gt = read(folder, n)
        acc = {}
        for (a, b, c), l in zip(faces, gt):
            pa, pb, pc = v[a], v[b], v[c]
            u = [pb[k] - pa[k] for k in range(3)]
            w = [pc[k] - pa[k] for k in range(3)]
            cr = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
            area = sum(x * x for x in cr) ** 0.5 / 2
            s = acc.setdefault(l, [0.0, 0.0, 0.0])
            s[0] += area
            s[1] += area * (pa[1] + pb[1] + pc[1]) / 3
            s[2] += area * (pa[2] + pb[2] + pc[2]) / 3
        total = sum(s[0] for s in acc.values())
        shares[n] = {l: s[0] / total for l, s in acc.items()}
        heights = {l: s[1] / s[0] for l, s in acc.items()}
        if 1 in heights and 3 in heights and heights[1] < heights[3]:
            swapped.add(n)
        desc = ", ".join(
            f"{l}: {100 * shares[n][l]:.1f} % at y {heights[l]:+.2f} z {acc[l][2] / acc[l][0]:+.2f}"
            for l in sorted(acc)
        )
        print(f"{n:>4}: {desc}{'   <- label 1 below label 3' if n in swapped else ''}")
    print(f"label 1 lowest (1 and 3 exchanged against the others): {sorted(swapped, key=int)}")

    def ceiling(fix):
        def part_set(n):
            ls = set(shares[n])
            if fix or n not in swapped:
                return ls
            return {({1: 3, 3: 1}).get(l, l) for l in ls}

        def sh(n):
            if not fix or n not in swapped:
                return shares[n]
            return {({1: 3, 3: 1}).get(l, l): x for l, x in shares[n].items()}

        per = {}
        for s in names:
            acc = []
            for t in names:
                if t == s:
                    continue
                if fix or (s in swapped) == (t in swapped):
                    acc.append(sum(x for l, x in sh(t).items() if l in part_set(s)))
                else:
                    # Geometrically perfect labels in the source's convention: only the
                    # label both conventions share (2, the seat) can agree.
                    acc.append(sh(t).get(2, 0.0))
            per[s] = sum(acc) / len(acc)
        return per

    for fix in (False, True):
        per = ceiling(fix)
        worst = min(per, key=per.get)
        print(
            f"one-source ceiling, {'consistent labels' if fix else 'files as they are'}: "
            f"mean {100 * sum(per.values()) / len(per):.1f} %, worst source {worst} "
            f"({100 * per[worst]:.1f} %)"
        )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "../shared/data/coseg_chairs")
