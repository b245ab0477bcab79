"""What each effect a scene names costs in wall time: the scene with every
effect on, then with each removed in turn.

usage: python3 -m cases.effect_cost SCENE [--set KEY=VALUE ...] [--repeats 2] [--out DIR] [--build build]

Effects: seepage (the gas: the scene then runs on mpm-solid alone), damage
(elastic_damage -> drucker_prager with the same cohesion and friction),
plasticity (drucker_prager -> elastic), friction (friction walls and
obstacles -> rollers), gravity, permeability coupling, Biot storage. An effect
the scene does not name is listed as such and not run. Variants run one at a
time with every core, `repeats` times each, and the shortest wall time counts
(shared machines are noisy); the ratio to the all-on run is measured within
this one invocation. Writes DIR/effect_cost.md and .csv (default
results/effect_cost_<scene name>), and the edited scenes beside them.
"""
import argparse
import csv
import os
import sys

import tomlkit

from .runs import run_one

PROGRAMS = {("mpm",): ("mpm_solid", "mpm-solid"), ("seepage",): ("seepage_fe", "seepage-fe"),
            ("mpm", "seepage"): ("coupler", "outburst")}


def materials(doc):
    return doc.get("mpm", {}).get("materials", [])


def drop(table, *keys):
    for k in keys:
        if k in table:
            del table[k]


def no_seepage(doc):
    if "seepage" not in doc["scene"]["solvers"] or "mpm" not in doc["scene"]["solvers"]:
        return False
    drop(doc, "seepage", "coupling")
    doc["scene"]["solvers"] = ["mpm"]
    return True


def swap_model(doc, old, new, dropped):
    """Materials of model `old` become `new`, without the keys only `old` reads."""
    found = False
    for m in materials(doc):
        if m.get("model") == old:
            m["model"] = new
            drop(m, *dropped)
            found = True
    return found


def no_damage(doc):
    return swap_model(doc, "elastic_damage", "drucker_prager",
                      ("tensile_strength", "residual_ratio", "ultimate_strain_ratio", "bulking_factor"))


def no_plasticity(doc):
    return swap_model(doc, "drucker_prager", "elastic", ("cohesion", "friction_angle", "dilation_angle", "fit"))


def no_friction(doc):
    found = False
    mpm = doc.get("mpm", {})
    walls = mpm.get("walls", {})
    for side in ("left", "right", "bottom", "top"):
        if walls.get(side) == "friction":
            walls[side] = "roller"
            found = True
    if found:
        drop(walls, "friction_coefficient")
    for o in mpm.get("obstacles", []):
        if o.get("contact", "friction") == "friction":
            o["contact"] = "roller"
            drop(o, "friction_coefficient")
            found = True
    return found


def no_gravity(doc):
    mpm = doc.get("mpm", {})
    if "gravity" not in mpm:
        return False
    del mpm["gravity"]
    return True


def no_permeability_coupling(doc):
    c = doc.get("coupling")
    if c is None or not c.get("permeability_coupling", True):
        return False
    c["permeability_coupling"] = False
    drop(c, "permeability")
    return True


def no_biot_storage(doc):
    c = doc.get("coupling")
    if c is None or not c.get("biot_storage", False):
        return False
    c["biot_storage"] = False
    drop(c, "fixed_stress", "dilatation_floor")
    return True


EFFECTS = [("seepage", no_seepage), ("damage", no_damage), ("plasticity", no_plasticity),
           ("friction", no_friction), ("gravity", no_gravity), ("permeability coupling", no_permeability_coupling),
           ("Biot storage", no_biot_storage)]


def program_for(doc, build, scene):
    solvers = tuple(sorted(doc["scene"]["solvers"]))
    if solvers not in PROGRAMS:
        sys.exit(f"effect_cost: {scene}: scene.solvers {list(solvers)} names no program")
    folder, name = PROGRAMS[solvers]
    return os.path.join(build, folder, name)


def particle_steps(out):
    """MPM particle-steps of a run (from its mpm_history.csv), or None."""
    path = os.path.join(out, "mpm_history.csv")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.DictReader(f))
    total, last_step = 0.0, 0
    for r in rows:
        step = int(r["step"])
        total += (step - last_step) * int(r["particles"])
        last_step = step
    return total


def timed(program, scene, overrides, out, repeats):
    """The shortest wall time of `repeats` runs on every core, or NaN and the failure."""
    best = float("inf")
    for _ in range(repeats):
        wall, note = run_one(program, scene, overrides, out, os.cpu_count() or 1)
        if note:
            return float("nan"), note
        best = min(best, wall)
    return best, ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--set", action="append", default=[], help="an override for every run")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--out")
    ap.add_argument("--build", default="build")
    args = ap.parse_args()
    scene = os.path.abspath(args.scene)
    try:
        with open(scene) as f:
            text = f.read()
        base = tomlkit.parse(text)
    except (OSError, tomlkit.exceptions.ParseError) as e:
        sys.exit(f"effect_cost: {args.scene}: {e}")
    name = os.path.splitext(os.path.basename(scene))[0]
    out = os.path.abspath(args.out or os.path.join("results", f"effect_cost_{name}"))
    os.makedirs(out, exist_ok=True)

    variants = [("every effect on", scene, program_for(base, args.build, scene))]
    skipped = []
    for label, remove in EFFECTS:
        doc = tomlkit.parse(text)
        if not remove(doc):
            skipped.append(label)
            continue
        # The edited scene lives in DIR: a mesh file it names must still be found.
        mesh = doc.get("seepage", {}).get("mesh", {})
        if "file" in mesh and not os.path.isabs(mesh["file"]):
            mesh["file"] = os.path.join(os.path.dirname(scene), mesh["file"])
        path = os.path.join(out, f"{name}_without_{label.replace(' ', '_')}.toml")
        with open(path, "w") as f:
            f.write(tomlkit.dumps(doc))
        variants.append((f"without {label}", path, program_for(doc, args.build, scene)))

    rows = []
    for label, path, program in variants:
        wall, note = timed(program, path, args.set, os.path.join(out, label.replace(" ", "_")), args.repeats)
        steps = particle_steps(os.path.join(out, label.replace(" ", "_"))) if not note else None
        rows.append({"variant": label, "program": os.path.basename(program), "wall_s": wall,
                     "particle_steps_per_s": steps / wall if steps else float("nan"), "note": note})
        print(f"{label}: {wall:.2f} s {note}", flush=True)

    full = rows[0]["wall_s"]
    for r in rows:
        r["ratio_to_all_on"] = r["wall_s"] / full
    with open(os.path.join(out, "effect_cost.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    lines = [f"# What each effect costs: `{os.path.relpath(scene)}`", "",
             f"Overrides: {', '.join(args.set) if args.set else 'none'}; the shortest of {args.repeats} runs each, "
             "one at a time on every core.", "",
             "A removed effect may also change the motion (and so the number of steps): the MPM throughput "
             "(particle-steps per second, from mpm_history.csv) separates the cost per step.", "",
             "| variant | program | wall [s] | of the all-on time | the effect's share | MPM particle-steps/s |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        share = "" if r is rows[0] else f"{1 - r['ratio_to_all_on']:.0%}"
        lines.append(f"| {r['variant']} | {r['program']} | {r['wall_s']:.2f} | {r['ratio_to_all_on']:.2f} | {share} "
                     f"{r['note'][:60]} | {r['particle_steps_per_s']:.3g} |")
    if skipped:
        lines += ["", f"Not named by the scene (nothing to remove): {', '.join(skipped)}."]
    with open(os.path.join(out, "effect_cost.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
