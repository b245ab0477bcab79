#!/usr/bin/python3
"""Run a scene once under every word a choice key takes, as the program itself
lists them (`PROGRAM SCENE --explain --format json`), so that a new scheme or
acceleration is run here without a list in this file or in CMake. Every run
must end with exit code 0; fewer than two choices fails (the key is then not
a choice, or the program did not list it).

With --models-in DIR, every model file DIR/NAME.cpp (a self-registering
model, named as its file) must be among the words: a model whose object the
linker dropped from the program would otherwise shorten the list unseen.

usage: every_choice.py PROGRAM SCENE KEY WORK_DIR [--models-in DIR] [--set key=value]...
"""
import json
import os
import subprocess
import sys


def choices(program, scene, key, overrides):
    out = subprocess.run([program, scene, "--explain", "--format", "json"] + overrides, check=True,
                         capture_output=True, text=True).stdout
    for entry in json.loads(out)["keys"]:
        if entry["key"] == key:
            return entry["choices"]
    sys.exit(f"{program} does not read {key} from {scene}")


def main():
    program, scene, key, work = sys.argv[1:5]
    overrides = sys.argv[5:]
    models = None
    if "--models-in" in overrides:
        at = overrides.index("--models-in")
        models = overrides[at + 1]
        overrides = overrides[:at] + overrides[at + 2:]
    words = choices(program, scene, key, overrides)
    if len(words) < 2:
        sys.exit(f"{key} takes {words}: not a choice")
    if models is not None:
        files = sorted(os.path.splitext(f)[0] for f in os.listdir(models) if f.endswith(".cpp"))
        missing = [f for f in files if f not in words]
        if missing:
            sys.exit(f"{program} does not offer {', '.join(missing)} for {key}, though {models} holds "
                     f"{', '.join(m + '.cpp' for m in missing)}: its registration did not reach the program")
    failed = []
    for word in words:
        command = [program, scene, "-q", "-o", os.path.join(work, word), "--overwrite",
                   "--set", f'{key}="{word}"'] + overrides
        code = subprocess.run(command, stdout=subprocess.DEVNULL).returncode
        print(f"{key} = \"{word}\": exit code {code}")
        if code != 0:
            failed.append(word)
    if failed:
        sys.exit(f"failed under {', '.join(failed)}")


if __name__ == "__main__":
    main()
