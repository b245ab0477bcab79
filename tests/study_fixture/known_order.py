#!/usr/bin/python3
"""A stand-in program for testing cases/study.py: takes a scene, -q, -o DIR,
--overwrite and --set model.KEY=VALUE like the real ones, and writes DIR/result.txt holding
the error C h^order of a method of known order (the scene's [model])."""
import argparse
import os
import sys
import tomllib


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("-q", action="store_true")
    ap.add_argument("-o", required=True)
    ap.add_argument("--overwrite", action="store_true")
    ap.add_argument("--set", action="append", default=[])
    args = ap.parse_args()
    with open(args.scene, "rb") as f:
        model = tomllib.load(f)["model"]
    for o in args.set:
        key, value = o.split("=", 1)
        if not key.startswith("model."):
            sys.exit(f"{args.scene}: unknown key {key}")
        model[key[6:]] = tomllib.loads(f"v = {value}")["v"]
    h = float(model["h"])
    os.makedirs(args.o, exist_ok=True)
    with open(os.path.join(args.o, "result.txt"), "w") as f:
        f.write(f"{model['constant'] * h ** model['order']!r}\n")


if __name__ == "__main__":
    main()
