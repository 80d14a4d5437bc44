#!/usr/bin/env python3
"""Scores coseg outputs on COSEG chairs (shapes/N.off, gt/N.seg per-face labels).

  segment OUT_DIR DATA_DIR        co-segmentation: per-vertex region ids -> per-face (majority of
                                  the 3 corners), best one-to-one matching of region ids to labels
                                  over the whole set, area-weighted.
  transfer SRC PAIRS_DIR DATA_DIR label transfer from chair SRC: PAIRS_DIR/<tgt>/ holds the output
                                  of `coseg pair SRC.off TGT.off -o PAIRS_DIR/<tgt>`; each target
                                  region takes the area-majority label of the source region with
                                  the same id; unlabelled area counts as wrong. Mean over targets.
  --gt-swap STEMS:A=B (first)     exchange labels A and B in those shapes' ground truth
                                  (101,102,103,109,110:1=3 gives the consistent labels).
Pure Python (no numpy), deterministic.
"""
import itertools, os, sys

from off_mesh import face_areas, read_off


def face_regions(vertex_regions, faces):
    out = []
    for f in faces:
        r = [vertex_regions[v] for v in f]
        out.append(r[1] if r[1] == r[2] else r[0])
    return out


def read_ints(path):
    with open(path) as f:
        return [int(l) for l in f if l.strip()]


def stems(data):
    return sorted((f[:-4] for f in os.listdir(os.path.join(data, "shapes")) if f.endswith(".off")), key=lambda s: int(s) if s.isdigit() else s)


# `--gt-swap STEMS:A=B` (before the command): exchange labels A and B in the ground truth of
# those shapes, e.g. `--gt-swap 101,102,103,109,110:1=3` for the five COSEG chairs whose files
# reverse back and legs (scripts/chairs_gt_audit.py; eval_propagate's flag of the same name).
GT_SWAP = ({}, set())


def load(data, stem):
    pos, faces = read_off(os.path.join(data, "shapes", stem + ".off"))
    area = face_areas(pos, faces)
    total = sum(area)
    gt = read_ints(os.path.join(data, "gt", stem + ".seg"))
    swap, swapped = GT_SWAP
    if stem in swapped:
        gt = [swap.get(l, l) for l in gt]
    return faces, [a / total for a in area], gt


def segment(out, data):
    # confusion[region][label] = area (each shape's area normalised to 1)
    conf, regions, labels, per_shape = {}, set(), set(), {}
    for s in stems(data):
        faces, area, gt = load(data, s)
        fr = face_regions(read_ints(os.path.join(out, s + ".regions.txt")), faces)
        local = {}
        for r, l, a in zip(fr, gt, area):
            conf[(r, l)] = conf.get((r, l), 0.0) + a
            local[(r, l)] = local.get((r, l), 0.0) + a
            regions.add(r)
            labels.add(l)
        per_shape[s] = local
    labels, regions = sorted(labels), sorted(r for r in regions if r >= 0)
    best, best_map = -1.0, None
    # One-to-one in either direction: with fewer region ids than labels (a run whose last
    # region is empty everywhere) some labels stay unmatched and count as wrong.
    if len(regions) >= len(labels):
        pairings = (list(zip(perm, labels)) for perm in itertools.permutations(regions, len(labels)))
    else:
        pairings = (list(zip(regions, perm)) for perm in itertools.permutations(labels, len(regions)))
    for pairs in pairings:
        score = sum(conf.get(rl, 0.0) for rl in pairs)
        if score > best:
            best, best_map = score, dict(pairs)
    n = len(per_shape)
    shape_acc = {s: sum(a for (r, l), a in c.items() if best_map.get(r) == l) for s, c in per_shape.items()}
    worst = min(shape_acc.items(), key=lambda kv: kv[1])
    print(f"co-segmentation: {100 * best / n:.1f} % area correctly labelled over {n} shapes "
          f"(best one-to-one map {best_map}); worst shape {worst[0]}: {100 * worst[1]:.1f} %")


def transfer(src, pairs, data):
    sfaces, sarea, sgt = load(data, src)
    accs = {}
    for t in stems(data):
        if t == src:
            continue
        d = os.path.join(pairs, t)
        ra = read_ints(os.path.join(d, "A.regions.txt")) if os.path.exists(os.path.join(d, "A.regions.txt")) else None
        if ra is None:
            cand = [f for f in os.listdir(d) if f.endswith(".regions.txt")]
            a_name = [f for f in cand if f.startswith(src + ".")][0]
            b_name = [f for f in cand if f.startswith(t + ".")][0]
            ra, rb = read_ints(os.path.join(d, a_name)), read_ints(os.path.join(d, b_name))
        fr = face_regions(ra, sfaces)
        votes = {}
        for r, l, a in zip(fr, sgt, sarea):
            votes.setdefault(r, {}).setdefault(l, 0.0)
            votes[r][l] += a
        label_of = {r: max(sorted(v), key=lambda l: v[l]) for r, v in votes.items()}
        tfaces, tarea, tgt = load(data, t)
        tr = face_regions(rb, tfaces)
        accs[t] = sum(a for r, l, a in zip(tr, tgt, tarea) if label_of.get(r) == l and r >= 0)
    mean = sum(accs.values()) / len(accs)
    worst = min(accs.items(), key=lambda kv: kv[1])
    print(f"transfer from {src}: mean {100 * mean:.1f} % over {len(accs)} targets; worst {worst[0]}: {100 * worst[1]:.1f} %")


if __name__ == "__main__":
    if sys.argv[1] == "--gt-swap":
        stems_, pair = sys.argv[2].split(":")
        a, b = (int(x) for x in pair.split("="))
        GT_SWAP[0].update({a: b, b: a})
        GT_SWAP[1].update(stems_.split(","))
        sys.argv = sys.argv[:1] + sys.argv[3:]
    if sys.argv[1] == "segment":
        segment(sys.argv[2], sys.argv[3])
    else:
        transfer(sys.argv[2], sys.argv[3], sys.argv[4])
