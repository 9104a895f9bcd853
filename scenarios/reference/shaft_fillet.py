"""Writes the stepped shaft of scenarios/long/shaft_fillet_3d.toml and its crack.

The shaft (axis z, lengths in mm) is a round bar of radius R1 = 20 from z = 0 to the
shoulder at z = L1 = 45.2, joined to a bar of radius R2 = 30 up to z = L1 + L2 = 75.2 by a
fillet of radius rho = 5: the quarter circle about (r, z) = (R1 + rho, L1 - rho) from the
toe (R1, L1 - rho) to the shoulder face (R1 + rho, L1). The profile is revolved in N = 96
steps into a closed triangulated surface (binary STL, outward normals). The crack is a
disc of radius a = 6 in the plane z = L1 - rho (the fillet's toe), centred on the shaft's
surface at (0, R1): the body cuts it, and the half inside the shaft is the crack, its
front the arc inside (found by Fissure from the body when the file gives none). The disc
is meshed in rings 0.6 apart (OBJ, triangles counterclockwise seen from +z). A drawing of
both (SVG, an oblique view) goes to docs/shaft_fillet.svg.

Usage: python3 shaft_fillet.py <scenario folder> <docs folder>."""
import math
import os
import struct
import sys

R1, R2, RHO, L1, L2, N = 20.0, 30.0, 5.0, 45.2, 30.0, 96
A, RINGS = 6.0, 10
ZC = L1 - RHO


def profile():
    """(r, z) from the small end's centre round to the large end's centre."""
    pts = [(0.0, 0.0), (R1, 0.0), (R1, ZC)]
    arc = 12
    for k in range(1, arc + 1):
        t = math.pi - 0.5 * math.pi * k / arc  # from the toe (angle pi) to the face (pi/2)
        pts.append((R1 + RHO + RHO * math.cos(t), ZC + RHO * math.sin(t)))
    pts += [(R2, L1), (R2, L1 + L2), (0.0, L1 + L2)]
    return pts


def shaft():
    """Triangles of the revolved profile, outward."""
    prof = profile()
    def ring(r, z, j):
        t = 2 * math.pi * (j % N) / N
        return (r * math.cos(t), r * math.sin(t), z)

    tris = []
    for (r0, z0), (r1, z1) in zip(prof, prof[1:]):
        for j in range(N):
            a, b = ring(r0, z0, j), ring(r0, z0, j + 1)
            c, d = ring(r1, z1, j + 1), ring(r1, z1, j)
            # The profile runs so that (a, b, c, d) faces outward.
            if r0 > 0:
                tris.append((a, b, d))
            if r1 > 0:
                tris.append((b, c, d))
    return tris


def disc():
    """Vertices and triangles of the crack disc, rings of 6k points."""
    verts = [(0.0, R1, ZC)]
    rings = [[0]]
    for k in range(1, RINGS + 1):
        first = len(verts)
        r = A * k / RINGS
        for i in range(6 * k):
            t = 2 * math.pi * i / (6 * k)
            verts.append((r * math.cos(t), R1 + r * math.sin(t), ZC))
        rings.append(list(range(first, first + 6 * k)))
    tris = []
    for k in range(RINGS):
        inner, outer = rings[k], rings[k + 1]
        ni, no = len(inner), len(outer)
        i = o = 0
        # Walk both rings by angle, advancing the one whose next point comes first.
        while i < ni or o < no:
            ti = (i + 1) / ni if i < ni else 2.0
            to = (o + 1) / no if o < no else 2.0
            if k == 0 or to <= ti:
                tris.append((inner[i % ni], outer[o % no], outer[(o + 1) % no]))
                o += 1
                if k == 0 and o == no:
                    break
            else:
                tris.append((inner[i % ni], outer[o % no], inner[(i + 1) % ni]))
                i += 1
    return verts, tris


def write_stl(path, tris):
    with open(path, "wb") as f:
        f.write(b"fissure shaft_fillet.py: stepped shaft, mm".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for p in t:
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")


def write_obj(path, verts, tris):
    with open(path, "w") as f:
        f.write("# fissure shaft_fillet.py: crack disc, mm\n")
        for v in verts:
            f.write("v %.9g %.9g %.9g\n" % v)
        for t in tris:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t))


def write_svg(path, shaft_tris, verts, crack_tris):
    """An oblique view: the shaft's profile lines and rings, the crack disc inside."""
    az, el = math.radians(25.0), math.radians(25.0)

    def view(p):
        x, y, z = p
        u = x * math.cos(az) - y * math.sin(az)
        w = x * math.sin(az) + y * math.cos(az)
        return 240 + 5.5 * u, 515 - 5.5 * (z * math.cos(el) - w * math.sin(el))

    lines = []
    prof = profile()
    for j in range(0, N, 4):
        t = 2 * math.pi * j / N
        pts = [view((r * math.cos(t), r * math.sin(t), z)) for r, z in prof]
        lines.append(("#888", pts))
    for r, z in prof[1:-1]:
        pts = [view((r * math.cos(2 * math.pi * j / N), r * math.sin(2 * math.pi * j / N), z))
               for j in range(N + 1)]
        lines.append(("#444", pts))
    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="480" height="600" '
           'viewBox="0 0 480 600" font-family="sans-serif" font-size="13">',
           '<rect width="480" height="600" fill="white"/>']
    for colour, pts in lines:
        d = " ".join("%.1f,%.1f" % p for p in pts)
        out.append('<polyline fill="none" stroke="%s" stroke-width="0.7" points="%s"/>'
                   % (colour, d))
    for t in crack_tris:
        pts = [verts[i] for i in t]
        inside = all(math.hypot(p[0], p[1]) <= R1 + 1e-9 for p in pts)
        d = " ".join("%.1f,%.1f" % view(p) for p in pts)
        out.append('<polygon fill="%s" stroke="none" points="%s"/>'
                   % ("#d62728" if inside else "#f4b6b6", d))
    out.append('<text x="10" y="20">Stepped shaft: radius 20 / 30 mm, fillet 5 mm</text>')
    out.append('<text x="10" y="38" fill="#d62728">the crack: the disc of radius 6 mm '
               'inside the shaft</text>')
    out.append('<text x="10" y="56" fill="#e08080">the disc outside the shaft '
               '(no crack there)</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    scen, docs = sys.argv[1], sys.argv[2]
    os.makedirs(scen, exist_ok=True)
    st = shaft()
    write_stl(os.path.join(scen, "shaft.stl"), st)
    v, t = disc()
    write_obj(os.path.join(scen, "crack.obj"), v, t)
    write_svg(os.path.join(docs, "shaft_fillet.svg"), st, v, t)
    print("%d shaft triangles, %d crack triangles" % (len(st), len(t)))
