"""Reading plain OFF meshes and their triangle areas, for the evaluation scripts beside it.

Pure Python (no numpy), deterministic.
"""


def read_off(path):
    """Positions (x, y, z tuples) and triangles (the first three corners of each face) of an
    ASCII OFF file; the header may run into the counts (`OFF4 2 0`)."""
    with open(path) as f:
        toks = f.read().split()
    i = 1 if toks[0].upper().startswith("OFF") else 0
    if toks[0].upper() != "OFF" and toks[0].upper().startswith("OFF"):
        toks = [toks[0][3:]] + toks[1:]
        i = 0
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


def face_areas(pos, faces):
    """The area of every triangle."""
    out = []
    for a, b, c in faces:
        pa, pb, pc = pos[a], pos[b], pos[c]
        u = [pb[k] - pa[k] for k in range(3)]
        v = [pc[k] - pa[k] for k in range(3)]
        w = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        out.append(0.5 * (w[0] ** 2 + w[1] ** 2 + w[2] ** 2) ** 0.5)
    return out
