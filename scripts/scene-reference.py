#!/usr/bin/env python3
"""Writes the manual's scene-key reference (docs/reference/) from what the
programs say: each shipped scene (cases/**/*.toml with a [scene] solvers) run
through its program with --explain --format json, the keys of all of a
program's scenes merged into one page, each key once, under its table.

usage: scene-reference.py [--build BUILD] [--check]
--check writes nothing: it prints a diff and exits 1 where a committed page
differs from what the programs say now (CTest runs it).

A key read without a default is required where it is read, but a program may
read it only when the scene gives it (scene.rest_fraction): such a key is
told apart by running the scene once more without it (--set replacing its
table by a copy that lacks it). A required key's absence stops the program
with an error naming it; an optional one's does not.
"""
import argparse
import difflib
import glob
import html
import json
import os
import re
import subprocess
import sys
import tomllib
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGES = os.path.join(ROOT, "docs", "reference")
GENERATOR = "scripts/scene-reference.py"
# Which program runs a scene, by its [scene] solvers: its path in the build, and what it simulates.
PROGRAMS = {
    "seepage-fe": (("seepage",), "seepage_fe/seepage-fe", "the gas seepage alone, by finite elements"),
    "mpm-solid": (("mpm",), "mpm_solid/mpm-solid", "the solid alone, by the material point method"),
    "outburst": (("seepage", "mpm"), "coupler/outburst", "the two coupled"),
}
# The fields of a record that describe the key (value and default belong to one scene).
DESCRIPTION = ("doc", "expects", "fallback", "range", "choices")


def shipped_scenes():
    """{program: [scene paths relative to the top folder]}, each list sorted."""
    scenes = {name: [] for name in PROGRAMS}
    for path in sorted(glob.glob(os.path.join(ROOT, "cases", "**", "*.toml"), recursive=True)):
        with open(path, "rb") as f:
            header = tomllib.load(f).get("scene")
        solvers = header.get("solvers") if isinstance(header, dict) else None
        if not solvers:
            continue  # a study's or another tool's file, not a scene
        runs = [name for name, (wanted, _, _) in PROGRAMS.items() if set(solvers) == set(wanted)]
        if not runs:
            sys.exit(f"{path}: [scene] solvers = {solvers}: no program runs that")
        scenes[runs[0]].append(os.path.relpath(path, ROOT))
    return scenes


def run_explain(build, program, scene, overrides=()):
    exe = os.path.join(build, PROGRAMS[program][1])
    if not os.access(exe, os.X_OK):
        sys.exit(f"{exe}: no such program (build it, or give --build)")
    command = [exe, scene, "--explain", "--format", "json"]
    for o in overrides:
        command += ["--set", o]
    return subprocess.run(command, capture_output=True, text=True, cwd=ROOT, timeout=300)


def explain(build, program, scene):
    """The records of the keys the program reads in the scene (--explain --format json)."""
    done = run_explain(build, program, scene)
    if done.returncode != 0:
        sys.exit(f"{program} {scene} --explain failed (exit code {done.returncode}):\n{done.stderr}")
    return json.loads(done.stdout)["keys"]


def toml_value(v):
    """A value of a scene as an inline TOML value (what --set takes)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)  # TOML writes 1e-10, inf and nan as Python does
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"no inline TOML for {v!r}")


def without(scene, key):
    """A --set that leaves the key (as the program names it: mpm.materials[0].density)
    out of the scene: its table, or the array of tables holding it, given again without it."""
    with open(os.path.join(ROOT, scene), "rb") as f:
        root = tomllib.load(f)
    parts = key.split(".")
    indexed = [i for i, p in enumerate(parts[:-1]) if "[" in p]
    # --set cannot name a table of an array: the whole array is given again.
    cut = indexed[-1] if indexed else len(parts) - 2
    node = root
    for p in parts[:cut]:
        name, _, index = p.partition("[")
        node = node[name] if not index else node[name][int(index.rstrip("]"))]
    name = parts[cut].partition("[")[0]
    copy = json.loads(json.dumps(node[name]))
    table = copy
    if indexed:
        table = table[int(parts[cut].partition("[")[2].rstrip("]"))]
    for p in parts[cut + 1:-1]:
        table = table[p]
    del table[parts[-1]]
    return ".".join(parts[:cut] + [name]) + "=" + toml_value(copy)


def without_it(build, program, scene, key):
    """What the program makes of the scene without the key: "required" (it
    stops, asking for the key), "optional" (it reads the scene) or "other" (it
    stops over another key, which the scene set up for this one). The
    message is common/scene.cpp's for a required key."""
    done = run_explain(build, program, scene, [without(scene, key)])
    if done.returncode == 0:
        return "optional"
    return "required" if "required key is missing" in done.stderr else "other"


def general(path):
    """A key's path without the indices of its arrays of tables:
    mpm.materials[0].density -> mpm.materials[].density."""
    return re.sub(r"\[\d+\]", "[]", path)


def anchor(path):
    """A key's or table's anchor on its page: the dotted path, indices dropped, each dot a hyphen."""
    return general(path).replace("[]", "").replace(".", "-")


def dimension(records):
    """'plane' or '3D' by the extent of the scene's grid or generated mesh; None if it has neither."""
    for r in records:
        if r["key"] in ("mpm.grid.size", "seepage.mesh.size"):
            return {"2": "plane", "3": "3D"}.get(r["expects"].split()[0])
    return None


# Choice keys that pick what else a table holds (a material's model, a boundary's type).
SELECTORS = ("model", "type")


def merge(runs):
    """One entry per key over the scenes' records (runs: [(scene, records)]),
    in the order the programs read them: {key: {"variants": {description:
    {scene: the key's path there}}, "set": [(scene, value)], "scenes": [the
    scenes reading it], "under": {selector: {words}}}}, "under" naming the
    words of its table's selector keys it was read with."""
    keys = {}
    for scene, records in runs:
        chosen = {}
        for r in records:
            table, _, name = r["key"].rpartition(".")
            if name in SELECTORS and r["expects"] == "one of":
                chosen.setdefault(table, {})[name] = r["value"]
        for r in records:
            entry = keys.setdefault(general(r["key"]), {"variants": {}, "set": [], "scenes": [], "under": {}})
            description = tuple(json.dumps(r[f]) for f in DESCRIPTION)
            entry["variants"].setdefault(description, {}).setdefault(scene, r["key"])
            if scene not in entry["scenes"]:
                entry["scenes"].append(scene)
            if not r["default"] and (scene, r["value"]) not in entry["set"]:
                entry["set"].append((scene, r["value"]))
            for selector, word in chosen.get(r["key"].rpartition(".")[0], {}).items():
                entry["under"].setdefault(selector, set()).add(word)
    return keys


def read_with(key, keys):
    """The selector words a key is read with, where it is not read with all
    that the scenes choose: 'model = "elastic_damage"'; None otherwise."""
    table, _, name = key.rpartition(".")
    told = []
    for selector, words in sorted(keys[key]["under"].items()):
        every = keys.get(f"{table}.{selector}", {}).get("under", {}).get(selector, set())
        if name != selector and words != every:
            told.append(f"{code(selector)} = " + " or ".join(code(w) for w in sorted(words)))
    return ", ".join(told) or None


def table_order(keys):
    """The tables in reading order, each top-level table's together:
    {table: [its keys]}."""
    tables, tops = {}, []
    for key in keys:
        tables.setdefault(table_of(key), []).append(key)
        if key.split(".")[0] not in tops:
            tops.append(key.split(".")[0])
    order = sorted(tables, key=lambda t: (tops.index(t.split(".")[0]), list(tables).index(t)))
    return {t: tables[t] for t in order}


def probe_required(build, program, keys, order):
    """Whether each variant of a key without a default is required
    ({(key, description): bool}), tried on the first of its scenes in `order`.
    A variant whose scene stops over another key (a 3D grid without its size
    is read as plane, and its gravity then has a value too many) is as the
    key's other variants are: required if one of them is."""
    trials = []
    for key, entry in keys.items():
        for description, paths in entry["variants"].items():
            if not json.loads(description[DESCRIPTION.index("fallback")]):
                scene = min(paths, key=order.index)
                trials.append(((key, description), scene, paths[scene]))
    with ThreadPoolExecutor(max_workers=2) as pool:
        found = dict(zip((t[0] for t in trials), pool.map(lambda t: without_it(build, program, *t[1:]), trials)))
    asked = {key for (key, _), outcome in found.items() if outcome == "required"}
    return {(key, d): outcome == "required" or (outcome == "other" and key in asked)
            for (key, d), outcome in found.items()}


def table_of(key):
    """The table a key belongs to (mpm.materials[].density -> mpm.materials[])."""
    return key.rsplit(".", 1)[0]


def table_heading(table):
    """A table as a scene writes its header: [mpm.grid], [[mpm.materials]]."""
    return f"[[{table[:-2]}]]" if table.endswith("[]") else f"[{table}]"


def as_written(text, expects):
    """A value as a scene writes it: the programs give a default bare (`0 m,
    0 m` for ["0 m", "0 m"]) and a quantity a scene sets without its quotes."""
    if text.startswith(("[", '"')):
        return text
    parts = [p.strip() for p in text.split(",")] if text else []
    if expects == "a list of" or re.match(r"\d+ values: ", expects):
        return "[" + ", ".join(f'"{p}"' for p in parts) + "]"
    if re.match(r"\d+ (numbers|integers)$", expects):
        return "[" + ", ".join(parts) + "]"
    if expects in ("a number", "an integer", "true or false"):
        return text
    return f'"{text}"'  # a word, a string or a quantity with its unit


def code(text):
    """Inline code that may hold backticks."""
    fence = "``" if "`" in text else "`"
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def prose(text):
    """A doc string as Markdown text: nothing in it read as HTML or emphasis."""
    return html.escape(text, quote=False).replace("*", r"\*")


def takes(expects, choices):
    """What a key takes, in words."""
    if expects in ("one of", "a list of"):
        words = ", ".join(code(f'"{c}"') for c in choices)
        return f"one of {words}" if expects == "one of" else f"a list of words from {words}"
    return prose(expects)


def variant_label(scenes, dims, all_scenes):
    """Which scenes a variant of a key comes from: 'plane scenes', '3D scenes' or their names."""
    for dim in ("plane", "3D"):
        if set(scenes) == {s for s in all_scenes if dims[s] == dim}:
            return f"{dim} scenes"
    return ", ".join(code(s) for s in scenes)


def by_variant(entry, dims, show):
    """show(description) for each of a key's variants: one text where they
    agree, else each with the scenes it holds in ([(label or None, text)]),
    plane scenes first."""
    texts = {}
    for description, paths in entry["variants"].items():
        texts.setdefault(show(description), []).extend(paths)
    if len(texts) == 1:
        return [(None, next(iter(texts)))]
    shown = [(variant_label(scenes, dims, entry["scenes"]), text) for text, scenes in texts.items()]
    return sorted(shown, key=lambda v: ("plane scenes", "3D scenes").index(v[0]) if v[0].endswith(" scenes") else 2)


def heading(level, path, text):
    """A heading with the anchor of `path` and the theme's permalink (the
    toc extension's own ids drop the dots: mpm.courant would be #mpmcourant)."""
    name = anchor(path)
    return (f'<h{level} id="{name}"><code>{html.escape(text)}</code>'
            f'<a class="headerlink" href="#{name}" title="Permanent link">&para;</a></h{level}>')


def key_block(key, keys, dims, needed):
    """The Markdown of one key: its heading, meaning, what it takes, its range,
    default and the scenes that set it."""
    field = lambda description, name: json.loads(description[DESCRIPTION.index(name)])

    def default(d):
        if field(d, "fallback"):
            return code(as_written(field(d, "fallback"), field(d, "expects")))
        return "required" if needed[(key, d)] else "none, optional (its meaning says what the program does without it)"

    entry = keys[key]
    lines = [heading(3, key, key), ""]
    for title, show in (("Meaning", lambda d: prose(field(d, "doc"))),
                        ("Takes", lambda d: takes(field(d, "expects"), field(d, "choices"))),
                        ("Range", lambda d: prose(field(d, "range")) or "any"),
                        ("Default", default)):
        shown = by_variant(entry, dims, show)
        if len(shown) > 1:
            lines.append(f"- **{title}:** " + "; ".join(f"*{label}:* {text}" for label, text in shown))
        elif shown[0][1] != "any":
            lines.append(f"- **{title}:** {shown[0][1]}")
    if read_with(key, keys):
        lines.append(f"- **Read with:** {read_with(key, keys)}")
    given = {}
    for scene, value in entry["set"]:
        given.setdefault(scene, []).append(code(as_written(value, field(next(iter(entry["variants"])), "expects"))))
    if given:
        lines.append("- **Set in:** " + "; ".join(f"{code(s)}: {', '.join(v)}" for s, v in given.items()))
    else:
        lines.append("- **Set in:** no shipped scene: all take the default")
    return lines + [""]


def program_page(build, program, runs):
    """The reference page of one program from its scenes' records (runs: [(scene, records)])."""
    keys = merge(runs)
    dims = {scene: dimension(records) for scene, records in runs}
    order = sorted(dims, key=lambda s: (dims[s] == "3D", len(dict(runs)[s]), s))
    needed = probe_required(build, program, keys, order)
    tables = table_order(keys)
    lines = [f"# {program}", "",
             f"The scene keys that `{program}` ({PROGRAMS[program][2]}) reads, from "
             f"`{program} SCENE --explain --format json` over the {len(runs)} shipped scenes it runs. "
             f"Generated by `{GENERATOR}`: change a key's declaration in the code, not this page. "
             "[How to read a key](index.md#reading-a-key).", "",
             "Tables: " + " · ".join(f"[{code(table_heading(t))}](#{anchor(t)})" for t in tables), ""]
    for table, members in tables.items():
        lines += [heading(2, table, table_heading(table)), ""]
        for key in members:
            lines += key_block(key, keys, dims, needed)
    lines.append("Scenes read: " + ", ".join(code(s) for s, _ in runs) + ".")
    return "\n".join(lines) + "\n"


INDEX = """# Scene-key reference

Every key a scene file may hold, one page per program, generated from what
the programs themselves say: each shipped scene (`cases/**/*.toml` with a
`[scene] solvers` list) is run through its program with
`--explain --format json`, which reads and checks the scene, lists each key
it read with its meaning, what it takes, its range and its default, and runs
nothing. A page holds the keys of all of its program's scenes, each once,
under the table that holds it, in the order the program reads them.

| program | runs the scenes with | shipped scenes |
|---|---|---|
{rows}

## Reading a key

- **Meaning:** what the key sets, in the program's own words.
- **Takes:** what the value is. A quantity ("a pressure", "a time", "2
  values: length") is a string of a number and its unit, such as `"3 MPa"` or
  `"0.1 m2/(MPa2 d)"`: any unit of that dimension is read, and a bare number
  is refused. "a number" and "an integer" take bare numbers. A choice lists
  its words; a list of words takes an array of them.
- **Range:** the values the program accepts; a quantity's limits are in SI
  units (an angle's in degrees). A value outside it stops the program with an
  error naming the file, the key and the range.
- **Default:** the value, as a scene would write it, that the program takes
  when the key is left out. "required": a scene that leaves it out is
  refused (found by running a shipped scene without it). "none, optional":
  there is no default, and without the key the program does without what it
  sets (its meaning says what).
- **Read with:** the words of its table's `model` or `type` under which the
  shipped scenes have the key read, where that is not every word they
  choose: a material's `friction_angle` is read under some models only.
- **Set in:** the shipped scenes that give the key, and the value each gives.
- Where a key means or takes something else in a 3D scene than in a plane
  one (the number of coordinates, say), or under another model, each variant
  is shown with the scenes it comes from.

A key that only a model or option no shipped scene chooses reads is not
listed: `PROGRAM SCENE --explain` on a scene that chooses it lists it.

## Anchors

Each key and each table has an anchor on its program's page: its dotted path
with the indices of arrays of tables dropped and each dot written as a
hyphen. `mpm.courant` is
[`outburst.md#mpm-courant`](outburst.md#mpm-courant),
`mpm.materials[0].youngs_modulus` is
[`outburst.md#mpm-materials-youngs_modulus`](outburst.md#mpm-materials-youngs_modulus),
the table `[mpm.grid]` is [`outburst.md#mpm-grid`](outburst.md#mpm-grid).
From a page in another folder of the manual, give the path to the page:
`../reference/mpm-solid.md#mpm-shape`. CTest's check of the built manual
fails on a link to an anchor that is not there.

## Keeping it current

    /usr/bin/python3 scripts/scene-reference.py --build build          # rewrites the pages
    /usr/bin/python3 scripts/scene-reference.py --build build --check  # compares only

The check is the CTest test "scene-key reference pages match what the
programs explain": a page that differs from what the programs say now fails
it, with the difference.
"""


def index_page(scenes):
    def solvers(program):
        return "solvers = [" + ", ".join(f'"{s}"' for s in PROGRAMS[program][0]) + "]"
    rows = "\n".join(f"| [`{p}`]({p}.md) | `{solvers(p)}` | {', '.join(code(s) for s in scenes[p])} |"
                     for p in PROGRAMS)
    return INDEX.format(rows=rows)


def pages(build):
    """{file name: text} of every page of the reference."""
    scenes = shipped_scenes()
    jobs = [(p, s) for p in PROGRAMS for s in scenes[p]]
    with ThreadPoolExecutor(max_workers=2) as pool:
        records = dict(zip(jobs, pool.map(lambda job: explain(build, *job), jobs)))
    out = {"index.md": index_page(scenes)}
    for program in PROGRAMS:
        out[f"{program}.md"] = program_page(build, program, [(s, records[(program, s)]) for s in scenes[program]])
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="the build folder holding the programs")
    ap.add_argument("--check", action="store_true", help="compare with the committed pages, write nothing")
    args = ap.parse_args()
    differ = []
    for name, text in pages(os.path.abspath(args.build)).items():
        path = os.path.join(PAGES, name)
        old = open(path, encoding="utf-8").read() if os.path.exists(path) else ""
        if old == text:
            continue
        differ.append(name)
        if args.check:
            sys.stdout.writelines(difflib.unified_diff(old.splitlines(True), text.splitlines(True),
                                                       f"docs/reference/{name} (committed)",
                                                       f"docs/reference/{name} (what the programs say)"))
        else:
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
    if args.check and differ:
        sys.exit(f"scene-reference: {', '.join(differ)} {'differs' if len(differ) == 1 else 'differ'} from what "
                 "the programs say: "
                 f"run {GENERATOR} --build BUILD and commit the pages")
    print(f"scene-reference: {'checked' if args.check else 'wrote'} docs/reference/, "
          f"{len(differ)} page(s) {'differ' if args.check else 'changed'}")


if __name__ == "__main__":
    main()
