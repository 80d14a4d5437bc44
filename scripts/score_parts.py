#!/usr/bin/env python3
"""Purity / coverage of a `coseg segment` output folder against a shipped collection's
ground truth, re-implementing coseg::evaluate::{part_purity, part_coverage} (grouped parts,
barycentric vertex areas, each shape at unit area, pooled over shapes).
usage: score_parts.py OUT_DIR COLLECTION_DIR"""
import json, os, sys

def read_obj(path):
    pos, faces = [], []
    for line in open(path):
        t = line.split()
        if not t: continue
        if t[0] == 'v': pos.append(tuple(map(float, t[1:4])))
        elif t[0] == 'f':
            idx = [int(x.split('/')[0]) for x in t[1:]]
            idx = [i - 1 if i > 0 else len(pos) + i for i in idx]
            for k in range(1, len(idx) - 1):
                faces.append((idx[0], idx[k], idx[k + 1]))
    return pos, faces

def vertex_areas(pos, faces):
    w = [0.0] * len(pos)
    for a, b, c in faces:
        pa, pb, pc = pos[a], pos[b], pos[c]
        u = [pb[k] - pa[k] for k in range(3)]; v = [pc[k] - pa[k] for k in range(3)]
        x = (u[1]*v[2]-u[2]*v[1], u[2]*v[0]-u[0]*v[2], u[0]*v[1]-u[1]*v[0])
        ar = 0.5 * (x[0]**2 + x[1]**2 + x[2]**2) ** 0.5
        for i in (a, b, c): w[i] += ar / 3.0
    return w

def ints(path):
    return [int(l) for l in open(path) if l.strip()]

def scores(cells, parts):
    reg = {}
    for (r, t), a in cells.items():
        e = reg.setdefault(r, [0.0, 0.0]); e[0] += a; e[1] = max(e[1], a)
    pur = sum(e[1] for e in reg.values()) / sum(e[0] for e in reg.values())
    cov = [max([a for (r, q), a in cells.items() if q == p] + [0.0]) / ar for p, ar in parts.items() if ar > 0]
    return pur, sum(cov) / len(cov)

def main(out, coll):
    m = json.load(open(os.path.join(coll, 'manifest.json')))
    group_of = {p: g for g, ms in m.get('part_groups', {}).items() for p in ms}
    names, of_part = [], []
    for p in m['parts']:
        n = group_of.get(p, p)
        if n not in names: names.append(n)
        of_part.append(names.index(n))
    cells, parts, per = {}, {}, {}
    for s in m['shapes']:
        pos, faces = read_obj(os.path.join(coll, s['mesh']))
        w = vertex_areas(pos, faces); tot = sum(w)
        truth = [of_part[l] for l in ints(os.path.join(coll, s['labels']))]
        found = ints(os.path.join(out, s['name'] + '.regions.txt'))
        assert len(truth) == len(found) == len(pos), s['name']
        lc, lp = {}, {}
        for a, t, f in zip(w, truth, found):
            a /= tot
            for C, P in ((cells, parts), (lc, lp)):
                P[t] = P.get(t, 0.0) + a
                if f >= 0: C[(f, t)] = C.get((f, t), 0.0) + a
        per[s['name']] = scores(lc, lp)
    p, c = scores(cells, parts)
    wp = min(per.items(), key=lambda kv: kv[1][0]); wc = min(per.items(), key=lambda kv: kv[1][1])
    print(f"purity {100*p:.1f} % coverage {100*c:.1f} %  (per shape alone: worst purity {wp[0]} {100*wp[1][0]:.1f} %, worst coverage {wc[0]} {100*wc[1][1]:.1f} %)")

if __name__ == '__main__':
    main(sys.argv[1], sys.argv[2])
