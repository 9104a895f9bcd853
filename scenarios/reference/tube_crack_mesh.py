"""Writes the [[crack]] mesh of a semi-elliptical inner-surface crack in a tube.

The crack lies in the plane z = z0 of a tube of inner radius R (axis z). In polar
coordinates (theta from +y towards +x, r), its front is the semi-ellipse measured from
the curved inner surface: r_f(theta) = R + a sqrt(1 - (R theta / c)^2) for
|R theta| <= c (a the depth, 2c the length along the bore), and the mesh reaches from
`overhang` inside the bore out to the front. Usage:
python3 tube_crack_mesh.py R a c z0 overhang spacing > mesh.toml (SI units, m)."""
import math
import sys

R, a, c, z0, over, h = map(float, sys.argv[1:7])
tmax = c / R
nt = max(2, math.ceil(2 * c / h))
nr = max(2, math.ceil((a + over) / h))
verts, tris, front = [], [], []
for i in range(nt + 1):
    t = -tmax + 2 * tmax * i / nt
    rf = R + a * math.sqrt(max(0.0, 1 - (R * t / c) ** 2))
    for j in range(nr + 1):
        r = (R - over) + (rf - (R - over)) * j / nr
        verts.append((r * math.sin(t), r * math.cos(t), z0))
    front.append(i * (nr + 1) + nr)
for i in range(nt):
    for j in range(nr):
        p = i * (nr + 1) + j
        q = p + nr + 1
        tris.append((p, q, q + 1))
        tris.append((p, q + 1, p + 1))
fmt = lambda v: "[" + ", ".join("%.9g" % x for x in v) + "]"
print("mesh = { vertices = [%s]," % ", ".join(fmt(v) for v in verts))
print("  triangles = [%s]," % ", ".join("[%d, %d, %d]" % t for t in tris))
print("  front = [%s] }" % ", ".join(str(k) for k in front))
