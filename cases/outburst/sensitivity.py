"""Sensitivity of the outburst case's headline numbers to the parameters the
paper does not give, and to resolution.

usage: python3 -m cases.outburst.sensitivity [--outburst build/coupler/outburst] [--out results/outburst_sensitivity]
                                              [--end-time "1 s"] [--only TEXT...] [--resume]
writes OUT/sensitivity.md and OUT/sensitivity.csv; one run per row (one at a
time: each uses every core), 11 minutes on 2 cores for the parameter rows;
--only runs the rows whose label holds one of the TEXTs (--only transfer: the grid
transfer rows, PIC share 0, 0.01, 0.05 and APIC at the shipped and the double
resolution, 40 minutes; --only "crack band" heterogeneous nonlocal: the
fracture rows). Each finished row is kept in its run folder
(row.json); --resume reads the rows an interrupted study finished with the
same overrides and end time instead of running them again.
"""
import argparse
import json
import os

from ..runs import run_one, write_rows
from .headline import headline
from .laws import SHIPPED, crack_band_scene, seam_mesh


# (label, overrides): each row changes one choice of outburst.toml.
VARIANTS = [
    ("as shipped", []),
    ("xi' = 1e2", ["coupling.permeability.xi_full=100"]),
    ("xi' = 1e4", ["coupling.permeability.xi_full=1e4"]),
    ("xi' = 1e6", ["coupling.permeability.xi_full=1e6"]),
    ("eta = 10", ["mpm.materials[0].ultimate_strain_ratio=10"]),
    ("residual ratio 0.3", ["mpm.materials[0].residual_ratio=0.3"]),
    ("floor/roof friction 0.2", ["mpm.obstacles[0].friction_coefficient=0.2",
                                 "mpm.obstacles[1].friction_coefficient=0.2"]),
    ("floor/roof friction 0.6", ["mpm.obstacles[0].friction_coefficient=0.6",
                                 "mpm.obstacles[1].friction_coefficient=0.6"]),
    ("bulking factor 1.0", ["mpm.materials[0].bulking_factor=1.0"]),
    ("bulking factor 1.3", ["mpm.materials[0].bulking_factor=1.3"]),
    ("grid 0.5 m", ['mpm.grid.cell_size="0.5 m"']),
    ("grid 0.25 m", ['mpm.grid.cell_size="0.25 m"']),
    ("3 x 3 particles per cell", ["mpm.bodies[0].particles_per_cell=3"]),
    # Particles 1/9 m apart fill 0.25 m seepage cells to 79 % at least (2 x 2,
    # 1/6 m apart, would leave some at 44 %: refused: docs/user-guide/bad-input.md).
    ("seepage mesh 0.25 m, 3 x 3 particles per cell", ["mpm.bodies[0].particles_per_cell=3", "FINE_MESH"]),
]
# The grid transfer (the PIC share of the FLIP/PIC blend, or APIC) at the
# shipped resolution and at twice it.
for _grid, _cells in [("1/3 m", []), ("1/6 m", ['mpm.grid.cell_size="0.16666666666666666 m"'])]:
    for _name, _setting in [("PIC 0 (pure FLIP)", ["mpm.flip_fraction=1.0"]), ("PIC 0.01", ["mpm.flip_fraction=0.99"]),
                            ("PIC 0.05", ["mpm.flip_fraction=0.95"]), ("APIC", ['mpm.transfer="apic"'])]:
        VARIANTS.append((f"transfer {_name}, grid {_grid}", _setting + _cells))
# Fracture with a length (issue 17), after the rows above so that their run
# folders keep their numbers: the crack band in place of eta, with each coal's
# G_f (laws.py), and heterogeneous coal (one seed each; the ensembles give the
# spread; under a crack band the mean G_f is E[s_f^2] E[1 / s_E] G_f, 1.37 G_f
# at m = 3).
VARIANTS += [
    ("crack band, G_f 2.4 J/m2 (outburst-prone)", ["CRACK_BAND=2.4 J/m2"]),
    ("crack band, G_f 16 J/m2 (non-outburst)", ["CRACK_BAND=16 J/m2"]),
    ("heterogeneous m = 3, seed 1", ["mpm.materials[0].heterogeneity={homogeneity_index=3, seed=1}"]),
    ("heterogeneous m = 1.5, seed 1", ["mpm.materials[0].heterogeneity={homogeneity_index=1.5, seed=1}"]),
    ("crack band 2.4 J/m2, heterogeneous m = 3, seed 1",
     ["CRACK_BAND=2.4 J/m2", "mpm.materials[0].heterogeneity={homogeneity_index=3, seed=1}"]),
    # Nonlocal damage over the shortest length the shipped cells resolve (two
    # cells: docs/theory/fracture.md), with the shipped eta.
    ("nonlocal damage, R = 0.75 m", ['mpm.materials[0].internal_length="0.75 m"']),
]
FINE_SEEPAGE_H = 0.25


def table(rows):
    """The sensitivity's markdown table; rows as sensitivity.csv holds them (numbers, or their text)."""
    lines = ["| variant | centre / top / bottom peak speed [m/s] | farthest [m] | ejected | fully damaged "
             "| gas released [m3/m] | steepest drop, first output / end [MPa/m] | left the grid "
             "| transfer / time step / damage, of the gas work | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("failure"):
            lines.append(f"| {r['variant']} | failed: {r['failure'][:120]} | | | | | | | | {r['wall_s']:.0f} |")
            continue
        damage = f"{r['damage_share']:.0e}" if r.get("damage_share") not in (None, "") else "-"
        lines.append(f"| {r['variant']} | {r['centre_m_per_s']:.1f} / {r['top_m_per_s']:.1f} / "
                     f"{r['bottom_m_per_s']:.1f} | {r['farthest_m']:.1f} | {r['ejected_fraction']:.1%} | "
                     f"{r['fully_damaged_fraction']:.1%} | {r['gas_released_m3_per_m']:.1f} | "
                     f"{r['first_drop_MPa_per_m']:.2f} / {r['last_drop_MPa_per_m']:.2f} | {int(r['left_grid'])} | "
                     f"{r['transfer_share']:.0%} / {r['step_share']:+.1%} / {damage} | {r['wall_s']:.0f} |")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--outburst", default="build/coupler/outburst")
    ap.add_argument("--out", default="results/outburst_sensitivity")
    ap.add_argument("--end-time", default="1 s")
    ap.add_argument("--only", nargs="+", default=[""], help="run only the rows whose label holds one of these texts")
    ap.add_argument("--resume", action="store_true", help="keep the rows an earlier run of the study finished")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    chosen = [(k, v) for k, v in enumerate(VARIANTS) if any(text in v[0] for text in args.only)]
    mesh = None
    if any("FINE_MESH" in o for _, (_, o) in chosen):
        mesh = f'seepage.mesh.file="{seam_mesh(args.out, FINE_SEEPAGE_H, f"seam_h{FINE_SEEPAGE_H:g}.msh")}"'
    for k, (label, overrides) in chosen:
        band = [o.split("=", 1)[1] for o in overrides if o.startswith("CRACK_BAND=")]
        scene = crack_band_scene(args.out, band[0]) if band else SHIPPED
        overrides = [mesh if o == "FINE_MESH" else o for o in overrides if not o.startswith("CRACK_BAND=")]
        run_dir = os.path.join(args.out, f"run_{k:02d}")
        overrides = [f'scene.end_time="{args.end_time}"'] + overrides
        kept = os.path.join(run_dir, "row.json")
        if args.resume and os.path.exists(kept):
            with open(kept) as f:
                earlier = json.load(f)
            # Rows from before the books held the time step's own error run again.
            if earlier["overrides"] == overrides and earlier.get("scene", SHIPPED) == scene and (
                    "failure" in earlier["row"] or "step_share" in earlier["row"]):
                rows.append(earlier["row"])
                print(f"{label}: kept from {kept}", flush=True)
                continue
        wall, failure = run_one(args.outburst, scene, overrides, run_dir,
                                os.cpu_count() or 1)
        if failure:
            # A setting that blows up is a result too: the row says where.
            print(f"sensitivity: {label}: {failure}", flush=True)
            row = {"variant": label, "wall_s": wall, "failure": failure.split("] ")[-1]}
        else:
            row = {"variant": label, "wall_s": wall, **headline(run_dir)}
            print(f"{label}: {row}", flush=True)
        rows.append(row)
        with open(kept, "w") as f:
            json.dump({"overrides": overrides, "scene": scene, "row": row}, f)
    write_rows(os.path.join(args.out, "sensitivity.csv"), rows)
    lines = ["# Outburst: sensitivity of the headline numbers", "",
             f"Each row changes one choice of `cases/outburst/outburst.toml`; {args.end_time} simulated.", ""]
    lines += table(rows)
    with open(os.path.join(args.out, "sensitivity.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
