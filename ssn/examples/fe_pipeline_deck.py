#!/usr/bin/env python3
"""Writes a CalculiX deck of a steel cantilever of NX x NY x NZ C3D8 elements
(800 x 100 x 100 mm, clamped at x = 0, mm-N-s units as in the fixture) and the scene the
`fe_pipeline` example times: 16 contact points on the tip face (normal y, gap 0.01 mm), a
point load on one of them, Craig-Bampton with 20 modes, H = 5.

    python3 ssn/examples/fe_pipeline_deck.py DIR [NX NY NZ]   # default 80 14 14: 54,000 dofs
    cd DIR && ccx big        # writes big.sti, big.mas, big.dof (SOLVER=MATRIXSTORAGE)

CalculiX 2.20 (`apt-get install calculix-ccx`) takes about a minute for the default mesh.
"""
import os
import sys


def node(i, j, k, nx, ny):
    """1-based number of the node at grid position (i, j, k)."""
    return 1 + i + (nx + 1) * j + (nx + 1) * (ny + 1) * k


def deck(nx, ny, nz):
    lx, ly, lz = 800.0, 100.0, 100.0
    lines = ["*HEADING", "big cantilever", "*NODE, NSET=NALL"]
    for k in range(nz + 1):
        for j in range(ny + 1):
            for i in range(nx + 1):
                lines.append(
                    f"{node(i, j, k, nx, ny)}, {lx * i / nx:g}, {ly * j / ny:g}, {lz * k / nz:g}"
                )
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=EALL")
    e = 0
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                e += 1
                n = [
                    node(i, j, k, nx, ny), node(i + 1, j, k, nx, ny),
                    node(i + 1, j + 1, k, nx, ny), node(i, j + 1, k, nx, ny),
                    node(i, j, k + 1, nx, ny), node(i + 1, j, k + 1, nx, ny),
                    node(i + 1, j + 1, k + 1, nx, ny), node(i, j + 1, k + 1, nx, ny),
                ]
                lines.append(f"{e}, " + ", ".join(map(str, n)))
    fixed = [node(0, j, k, nx, ny) for k in range(nz + 1) for j in range(ny + 1)]
    lines.append("*NSET, NSET=FIXED")
    for s in range(0, len(fixed), 10):
        lines.append(", ".join(map(str, fixed[s:s + 10])))
    lines += [
        "*BOUNDARY", "FIXED, 1, 3", "*MATERIAL, NAME=STEEL", "*ELASTIC", "210000., 0.3",
        "*DENSITY", "7.85e-9", "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL", "*STEP",
        "*FREQUENCY, SOLVER=MATRIXSTORAGE", "10", "*END STEP",
    ]
    return "\n".join(lines) + "\n"


def scene(nx, ny, nz):
    """The scene: 16 tip nodes on a 4 x 4 grid of the tip face, loaded at one of them."""
    js = [round(ny * f) for f in (1 / 7, 5 / 14, 9 / 14, 6 / 7)]
    ks = [round(nz * f) for f in (1 / 7, 5 / 14, 9 / 14, 6 / 7)]
    tips = [node(nx, j, k, nx, ny) for k in ks for j in js]
    loaded = node(nx, js[1], ks[1], nx, ny)
    t = [
        'title = "CalculiX cantilever, 16 tip contacts"', "[model]", 'format = "calculix"',
        'stiffness = "big.sti"', 'mass = "big.mas"', 'dof_map = "big.dof"',
        "[damping]", "zeta = 0.05",
        "[forcing]", f"node = {loaded}", "component = 2", "amplitude = 1000.0",
        "omega_ratio = 0.8", "[output]", f"node = {loaded}", "component = 2",
        "[solver]", "harmonics = 5", "[reduction]", 'method = "craig-bampton"', "modes = 20",
    ]
    for n in tips:
        t += ["", "[[contact.point]]", f"node = {n}", "component = 2", "gap = 0.01"]
    return "\n".join(t) + "\n"


def main():
    out = sys.argv[1]
    nx, ny, nz = (int(a) for a in (sys.argv[2:5] if len(sys.argv) >= 5 else (80, 14, 14)))
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "big.inp"), "w") as f:
        f.write(deck(nx, ny, nz))
    with open(os.path.join(out, "big.toml"), "w") as f:
        f.write(scene(nx, ny, nz))
    print(f"{out}/big.inp: {(nx + 1) * (ny + 1) * (nz + 1)} nodes, {nx * ny * nz} elements, "
          f"{3 * nx * (ny + 1) * (nz + 1)} free dofs; now run `ccx big` in {out}")


if __name__ == "__main__":
    main()
