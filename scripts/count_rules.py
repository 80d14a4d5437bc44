#!/usr/bin/env python3
"""Rules for the number of parts, compared offline on part trees (docs/PARTS.md).

Usage: count_rules.py CUTS.txt TREES.jsonl

CUTS.txt: per set a line `## NAME` then `eval_parts DIR --features auto --all-cuts default`'s
lines (`all-cuts N: PURITY COVERAGE`); TREES.jsonl: the same sets' `--dump-tree` lines, in the
same order. Prints, per set, the count each rule chooses (`*`: the cut meets the bar, purity
>= 85 and coverage >= 75) and the totals: sets meeting the bar, counts within 3..5.

Rules:
  otsu      Otsu's split of the merge costs (parts::choose_part_count).
  siblings  Otsu's count, raised until every merge made over a sibling link alone (groups that
            neither touch on half of the shapes nor are mirror pairs or copies) is refused.
  shapes    Otsu's criterion summed over shapes, each shape's own cost of each merge of the
            collection's tree (the thickness term and the concave term of the tree's cost,
            from that shape alone, plus the sibling surcharge where the tree paid it).
  votes     the (upper) median over shapes of each shape's own Otsu count on those costs.
"""
import json
import re
import sys

SIBLING_COST = 0.3  # the tree's surcharge (src/parts/geometric_part_tree.rs), not a choice here


def load(cuts, trees):
    blocks = open(cuts).read().split("## ")[1:]
    lines = [json.loads(l) for l in open(trees)]
    sets = []
    for text, s in zip(blocks, lines):
        s["name"] = text.split("\n")[0].strip()
        s["scores"] = {
            int(m[1]): (float(m[2]), float(m[3]))
            for m in re.finditer(r"all-cuts (\d+): ([\d.]+) ([\d.]+)", text)
        }
        s["costs"] = [m[2] for m in s["merges"]]
        members = [[x] for x in range(s["leaves"])]
        for a, b, _ in s["merges"]:
            members.append(members[a] + members[b])
        s["members"] = members
        for sh in s["shapes"]:
            sh["B"] = {}
            for x, y, length, concave in sh["bd"]:
                sh["B"][(x, y)] = sh["B"][(y, x)] = (length, concave)
        links = {tuple(p) for p in s["mirrors"] + s["copies"]}
        s["links"] = links | {(b, a) for a, b in links}
        sets.append(s)
    return sets


def meets(s, n):
    p, c = s["scores"].get(n, (0, 0))
    return p >= 85 and c >= 75


def between(c, n):
    made, refused = c[: len(c) + 1 - n], c[len(c) + 1 - n :]
    wa, wb = len(made) / len(c), len(refused) / len(c)
    return wa * wb * (sum(refused) / len(refused) - sum(made) / len(made)) ** 2


def otsu(c, max_parts=8):
    best = (-1.0, 2)
    for n in range(2, min(max_parts, len(c)) + 1):
        b = between(c, n)
        if b > best[0]:
            best = (b, n)
    return best[1]


def touching(s, A, B):
    shapes = len(s["shapes"])
    for x in A:
        for y in B:
            k = sum(1 for sh in s["shapes"] if (x, y) in sh["B"])
            if k > 0 and 2 * k >= shapes:
                return True
    return False


def by_siblings(s, k):
    a, b, _ = s["merges"][k]
    A, B = s["members"][a], s["members"][b]
    linked = any((x, y) in s["links"] for x in A for y in B)
    return not linked and not touching(s, A, B)


def siblings_rule(s, max_parts=8):
    n, leaves = otsu(s["costs"], max_parts), s["leaves"]
    for k in range(len(s["merges"])):
        if k < leaves - n and by_siblings(s, k):
            n = max(n, min(max_parts, leaves - k))
    return n


def shape_costs(s):
    out = []
    for sh in s["shapes"]:
        t, costs = sh["lnt"], []
        for k, (a, b, _) in enumerate(s["merges"]):
            A, B = s["members"][a], s["members"][b]
            d = [abs(t[x] - t[y]) for x in A for y in B if t[x] is not None and t[y] is not None]
            shares = [
                sh["B"][(x, y)][1] / sh["B"][(x, y)][0]
                for x in A
                for y in B
                if (x, y) in sh["B"] and sh["B"][(x, y)][0] > 0
            ]
            cost = (max(d) if d else 0.0) + (sum(shares) / len(shares) if shares else 0.0)
            costs.append(cost + (SIBLING_COST if by_siblings(s, k) else 0.0))
        out.append(costs)
    return out


def shapes_rule(s, max_parts=8):
    per = shape_costs(s)
    best = (-1.0, 2)
    for n in range(2, min(max_parts, len(s["costs"])) + 1):
        j = sum(between(c, n) for c in per)
        if j > best[0]:
            best = (j, n)
    return best[1]


def votes_rule(s, max_parts=8):
    counts = sorted(otsu(c, max_parts) for c in shape_costs(s))
    return counts[len(counts) // 2]


def main():
    sets = load(sys.argv[1], sys.argv[2])
    rules = {
        "otsu": lambda s: otsu(s["costs"]),
        "siblings": siblings_rule,
        "shapes": shapes_rule,
        "votes": votes_rule,
    }
    totals = {r: [0, 0] for r in rules}
    for s in sets:
        row = []
        for r, f in rules.items():
            n = f(s)
            totals[r][0] += meets(s, n)
            totals[r][1] += 3 <= n <= 5
            row.append(f"{r} {n}{'*' if meets(s, n) else ' '}")
        print(f"{s['name']:16s} " + "  ".join(row))
    for r, (bar, count) in totals.items():
        print(f"{r}: bar {bar} of {len(sets)}, count within 3..5 on {count}")


if __name__ == "__main__":
    main()
