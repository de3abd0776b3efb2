#!/usr/bin/env python3
"""Writes the reference office as RADIANCE input: materials, geometry, sky, sensors and suns.

The glass is in glass.rad of its own, so that the three-phase methods can leave it out and use
window.rad (the same panes as an rfluxmtx window) and skydome.rad instead.

One or more copies of a south-facing side-lit office (3.6 m wide, 8.2 m deep, 2.8 m high) stand
side by side behind a 0.2 m facade; every value and its source is in README.md here. x points
east, y north (into the room), z up; the glass faces south (-y).

    make_office.py [--offices N] [--blinds] [--nx 25] [--ny 57] [--out DIR]
"""
import argparse
import math
import os
import sys


def polygon(out, mod, name, pts):
    out.append(f"{mod} polygon {name}\n0\n0\n{3 * len(pts)}\n")
    for p in pts:
        out.append("    {:.6g} {:.6g} {:.6g}\n".format(*p))


def box_faces(out, mod, name, x0, x1, y0, y1, z0, z1):
    """The six faces of an axis-aligned box, facing outwards."""
    polygon(out, mod, name + "_b", [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)])
    polygon(out, mod, name + "_t", [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)])
    polygon(out, mod, name + "_s", [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)])
    polygon(out, mod, name + "_n", [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)])
    polygon(out, mod, name + "_w", [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)])
    polygon(out, mod, name + "_e", [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--offices", type=int, default=1, help="offices side by side (1, 2, 10)")
    ap.add_argument("--blinds", action="store_true", help="add exterior venetian blinds")
    ap.add_argument("--nx", type=int, default=25, help="sensor columns per office (east-west)")
    ap.add_argument("--ny", type=int, default=57, help="sensor rows per office (north-south)")
    ap.add_argument("--width", type=float, default=3.6)
    ap.add_argument("--depth", type=float, default=8.2)
    ap.add_argument("--height", type=float, default=2.8)
    ap.add_argument("--wwr", type=float, default=0.40, help="window-to-wall ratio (interior)")
    ap.add_argument("--sill", type=float, default=0.8)
    ap.add_argument("--window-width", type=float, default=3.4)
    ap.add_argument("--sensor-height", type=float, default=1.0)
    ap.add_argument("--out", default="model")
    a = ap.parse_args()
    if a.offices < 1 or a.nx < 1 or a.ny < 1:
        sys.exit("make_office.py: --offices, --nx and --ny must be positive")
    W, D, H, T = a.width, a.depth, a.height, 0.2  # T: wall thickness
    win_h = a.wwr * W * H / a.window_width
    head = a.sill + win_h
    if not (0 < a.window_width <= W and 0 <= a.sill and head <= H):
        sys.exit(f"make_office.py: the window ({a.window_width} x {win_h:.3f} m from a sill of "
                 f"{a.sill} m) does not fit a {W} x {H} m wall")
    os.makedirs(a.out, exist_ok=True)

    mat = [
        "# Reference office materials (README.md: values and sources)\n",
        "void plastic floor_mat 0 0 5 0.2 0.2 0.2 0 0\n",
        "void plastic wall_mat 0 0 5 0.5 0.5 0.5 0 0\n",
        "void plastic ceiling_mat 0 0 5 0.8 0.8 0.8 0 0\n",
        "void plastic facade_mat 0 0 5 0.35 0.35 0.35 0 0\n",
        "void plastic mullion_mat 0 0 5 0.5 0.5 0.5 0 0\n",
        # Visible transmittance 0.65 at normal incidence, as transmissivity by RADIANCE's formula
        # (sqrt(.8402528435 + .0072522239 T^2) - .9166530661) / .0036261119 / T.
        "void glass glass_mat 0 0 3 0.7085 0.7085 0.7085\n",
        "void metal blind_mat 0 0 5 0.7 0.7 0.7 0 0\n",
    ]
    geo = ["# Reference office geometry, written by make_office.py\n"]
    blinds = ["# Exterior blinds of the reference office, written by make_office.py\n"]
    # The first window's glass and slats as genBSDF takes a system (three- and five-phase with
    # blinds): x along the window (from its east jamb), y up (from the sill), z towards the room,
    # the glass at z = 0 and the slats beyond it (a rotation of the office's axes).
    system = ["# The glazing and blinds of one window for genBSDF, written by make_office.py\n",
              mat[-2], mat[-1]]
    frame = ["# The blinds' head boxes and guides, written by make_office.py\n"]
    system_dim = []
    glass = ["# The glazing of the reference office, written by make_office.py\n"]
    window = [
        "# The window for rfluxmtx (V and D of the three-phase method), written by make_office.py:\n",
        "# the scene's glass left out, Klems full bins with up along +z\n",
        "void glow window_glow 0 0 4 1 1 1 0\n",
        "#@rfluxmtx h=kf u=Z\n",
    ]
    pitch = W + T  # offices side by side, each with its own partition walls
    x_win0 = (W - a.window_width) / 2
    for k in range(a.offices):
        o = k * pitch
        n = f"office{k}"
        x0, x1 = o, o + W
        polygon(geo, "floor_mat", n + "_floor", [(x0, 0, 0), (x1, 0, 0), (x1, D, 0), (x0, D, 0)])
        polygon(geo, "ceiling_mat", n + "_ceiling", [(x0, 0, H), (x0, D, H), (x1, D, H), (x1, 0, H)])
        polygon(geo, "wall_mat", n + "_north", [(x0, D, 0), (x1, D, 0), (x1, D, H), (x0, D, H)])
        polygon(geo, "wall_mat", n + "_west", [(x0, 0, 0), (x0, D, 0), (x0, D, H), (x0, 0, H)])
        polygon(geo, "wall_mat", n + "_east", [(x1, 0, 0), (x1, 0, H), (x1, D, H), (x1, D, 0)])
        # The south wall: interior face (y = 0) and exterior face (y = -T) around the window,
        # and the window's reveals; the glass sits in the middle of the wall.
        wx0, wx1, wz0, wz1 = o + x_win0, o + x_win0 + a.window_width, a.sill, head
        for face, y, mod in (("in", 0.0, "wall_mat"), ("out", -T, "facade_mat")):
            rects = [(x0, x1, 0, wz0), (x0, x1, wz1, H), (x0, wx0, wz0, wz1), (wx1, x1, wz0, wz1)]
            for i, (u0, u1, v0, v1) in enumerate(rects):
                if u1 - u0 < 1e-9 or v1 - v0 < 1e-9:
                    continue
                pts = [(u0, y, v0), (u1, y, v0), (u1, y, v1), (u0, y, v1)]
                if face == "in":
                    pts.reverse()  # facing the room (+y)
                polygon(geo, mod, f"{n}_south_{face}{i}", pts)
        polygon(geo, "mullion_mat", n + "_sill", [(wx0, -T, wz0), (wx0, 0, wz0), (wx1, 0, wz0), (wx1, -T, wz0)])
        polygon(geo, "mullion_mat", n + "_head", [(wx0, -T, wz1), (wx1, -T, wz1), (wx1, 0, wz1), (wx0, 0, wz1)])
        polygon(geo, "mullion_mat", n + "_jamb_w", [(wx0, -T, wz0), (wx0, -T, wz1), (wx0, 0, wz1), (wx0, 0, wz0)])
        polygon(geo, "mullion_mat", n + "_jamb_e", [(wx1, -T, wz0), (wx1, 0, wz0), (wx1, 0, wz1), (wx1, -T, wz1)])
        pane = [(wx0, -T / 2, wz0), (wx1, -T / 2, wz0), (wx1, -T / 2, wz1), (wx0, -T / 2, wz1)]
        polygon(glass, "glass_mat", n + "_glass", pane)
        # The same pane as the three-phase methods' window: facing the room, so that rfluxmtx's
        # receiver takes rays from inside (V) and its sender shoots from the back, outwards (D).
        polygon(window, "window_glow", n + "_window", pane[::-1])
        if k + 1 < a.offices:  # the partition between this office and the next
            box_faces(geo, "wall_mat", f"{n}_partition", x1, x1 + T, 0, D, 0, H)
        if a.blinds:
            # Exterior venetian blinds: 80 mm slats every 70 mm, tilted 45 degrees (outer edge
            # down), 1 mm thick, their inner edges 50 mm in front of the facade, across the
            # window's width, with a head box above and side guides, so no sun passes around
            # them. They go to blinds.rad: LM-83's ASE is computed without them.
            slat, spacing, tilt, thick = 0.08, 0.07, math.radians(45), 0.001
            dy, dz = slat / 2 * math.cos(tilt), slat / 2 * math.sin(tilt)
            yc = -T - 0.05 - dy  # slat centre: the inner edge is 50 mm off the facade
            y_out = yc - dy - 0.01  # the outer edge, and 10 mm beyond for the guides
            count = int(math.ceil(win_h / spacing))
            nx, nz = -math.sin(tilt), math.cos(tilt)  # slat normal
            for i in range(count):
                zc = wz1 - (i + 0.5) * spacing
                for side, off in (("top", thick / 2), ("bot", -thick / 2)):
                    yo, zo = nx * off, nz * off
                    pts = [(wx0, yc - dy + yo, zc - dz + zo), (wx1, yc - dy + yo, zc - dz + zo),
                           (wx1, yc + dy + yo, zc + dz + zo), (wx0, yc + dy + yo, zc + dz + zo)]
                    if side == "top":
                        pts.reverse()
                    polygon(blinds, "blind_mat", f"{n}_slat{i}_{side}", pts)
                    if k == 0:
                        polygon(system, "blind_mat", f"slat{i}_{side}",
                                [(wx1 - x, z - wz0, y + T / 2) for x, y, z in pts])
            if k == 0:
                polygon(system, "glass_mat", "pane", [(wx1 - x, z - wz0, y + T / 2) for x, y, z in pane])
            z_low = wz1 - count * spacing - dz
            # The head box and guides also go to blinds_frame.rad: outside the slats' BSDF, the
            # three- and five-phase methods' D matrices see them as geometry.
            # The first window's go to the genBSDF system too, outside its -dim box (the window's
            # area): they close the cavity between facade and slats, as in the DC run.
            first_frame = []
            for out in (blinds, frame, first_frame):
                box_faces(out, "blind_mat", f"{n}_headbox", wx0 - 0.02, wx1 + 0.02, y_out,
                          -T - 0.001, wz1, wz1 + 0.06)
                for side, x in (("w", wx0 - 0.02), ("e", wx1)):
                    box_faces(out, "blind_mat", f"{n}_guide_{side}", x, x + 0.02, y_out,
                              -T - 0.001, z_low, wz1)
            if k == 0:
                for line in first_frame:
                    w = line.split()
                    if line.startswith("    ") and len(w) == 3:
                        x, y, z = map(float, w)
                        line = "    {:.6g} {:.6g} {:.6g}\n".format(wx1 - x, z - wz0, y + T / 2)
                    system.append(line)
                z_outer = min(yy + T / 2 for yy in (yc - dy - thick, yc + dy + thick))
                system_dim = [0, wx1 - wx0, 0, wz1 - wz0, z_outer, 0]

    sky = [
        "# The sky and ground as one glow sphere, binned by reinhart.cal (bin 0 is the ground)\n",
        "void glow skyglow 0 0 4 1 1 1 0\n",
        "skyglow source sky 0 0 4 0 0 1 360\n",
    ]
    # The same sky and ground for rfluxmtx (D), as in the LBNL tutorial's skyglow.rad.
    skydome = [
        "# Ground and sky for rfluxmtx, written by make_office.py: ground one bin, sky Reinhart MF:1\n",
        "#@rfluxmtx u=+Y h=u\n",
        "void glow groundglow 0 0 4 1 1 1 0\n",
        "groundglow source ground 0 0 4 0 0 -1 180\n",
        "#@rfluxmtx u=+Y h=r1\n",
        "void glow skyglow 0 0 4 1 1 1 0\n",
        "skyglow source skydome 0 0 4 0 0 1 180\n",
    ]
    # Suns at the centres of the Reinhart MF:6 patches (RADIANCE's reinsrc.cal with x1 = x2 = .5),
    # for the direct-sun coefficients of ASE; bins come from reinhart.cal, so the order is free.
    suns = ["void light solar 0 0 3 1e6 1e6 1e6\n"]
    mf = 6
    alpha = math.radians(90 / (7 * mf + 0.5))
    rows = [mf * (30, 30, 24, 24, 18, 12, 6)[r // mf] for r in range(7 * mf)] + [1]
    sun_id = 0
    for r, count in enumerate(rows):
        alt = (r + 0.5) * alpha
        for c in range(count):
            azi = 2 * math.pi * c / count
            sun_id += 1
            d = (math.sin(azi) * math.cos(alt), math.cos(azi) * math.cos(alt), math.sin(alt))
            suns.append("solar source sun{} 0 0 4 {:.8f} {:.8f} {:.8f} 0.533\n".format(sun_id, *d))
    # Sensors on a cell-centred grid: nx x ny cells of (W/nx) x (D/ny) per office.
    pts = []
    for k in range(a.offices):
        for j in range(a.ny):
            for i in range(a.nx):
                x = k * pitch + (i + 0.5) * W / a.nx
                y = (j + 0.5) * D / a.ny
                pts.append(f"{x:.6f} {y:.6f} {a.sensor_height:.6f} 0 0 1\n")
    area = W * D / (a.nx * a.ny)

    def write(name, lines):
        with open(os.path.join(a.out, name), "w") as f:
            f.writelines(lines)

    write("materials.rad", mat)
    # Black surfaces for the direct-only matrices of the five-phase method (V_d, D_d).
    black = ["# The reference office's materials made black, for V_d and D_d (five-phase)\n"]
    for line in mat[1:]:
        w = line.split()
        black.append(" ".join(w[:3] + ["0 0 5 0 0 0 0 0"]) + "\n" if w[1] in ("plastic", "metal")
                     else line)
    write("materials_black.rad", black)
    write("office.rad", geo)
    write("glass.rad", glass)
    write("window.rad", window)
    write("blinds.rad", blinds)
    write("blinds_system.rad", system)
    write("blinds_frame.rad", frame)
    write("blinds_system.dim", ["-dim " + " ".join(f"{v:.6g}" for v in system_dim) + "\n"]
          if a.blinds else [])
    write("skydome.rad", skydome)
    write("sky.rad", sky)
    write("suns.rad", suns)
    write("sensors.pts", pts)
    write("grids.txt", [f"office{k} {a.nx * a.ny}\n" for k in range(a.offices)])
    write("sensor_area.txt", [f"{area:.8f}\n"] * len(pts))
    print(f"make_office.py: {a.offices} office(s), {len(pts)} sensors on a {a.nx} x {a.ny} "
          f"cell-centred grid ({W / a.nx:.4f} x {D / a.ny:.4f} m), window {a.window_width} x "
          f"{win_h:.3f} m (sill {a.sill} m, head {head:.3f} m){', exterior blinds' if a.blinds else ''}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
