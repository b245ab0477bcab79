#!/usr/bin/python3
"""An output folder serves one run at a time: a second run while the first
lives is refused naming it (program, pid, start time); once the first is
killed (kill -9) its stale lock blocks nothing, but its files are replaced
only with --overwrite, which removes the earlier run's extra snapshots; -o
naming a file is refused with exit code 2. Each run lists the files it writes
in the folder's .run.manifest, and --overwrite removes those alone: a file
like a run's output that no run listed (a user's my_survey_data.h5) is
neither removed nor written beside, the run refused naming it (before, issue
57: removed); other files stay. A folder removed while a run writes there
stops the run with exit code 1, saying so (before: "0 MB free on its disk").

usage: output_folder.py MPM_SOLID SCENE WORK_DIR"""
import os
import shutil
import signal
import subprocess
import sys
import time


def run(program, scene, out, *extra):
    done = subprocess.run([program, scene, "-q", "-o", out, *extra], capture_output=True, text=True)
    lines = done.stderr.strip().splitlines()
    return done.returncode, lines[-1] if lines else ""


def main():
    program, scene, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    out = os.path.join(work, "run")
    failures = []

    def expect(what, result, code, *words):
        print(f"{what}: exit {result[0]}: {result[1]}")
        if result[0] != code or not all(w in result[1] for w in words):
            failures.append(f"{what}: exit {result[0]} '{result[1]}', expected {code} with {words}")

    # A long run with many snapshots, killed once it has written more than a
    # rerun of the scene writes (11).
    first = subprocess.Popen([program, scene, "-q", "-o", out, "--set", 'scene.end_time="10 s"', "--set",
                              'output.interval="0.001 s"'], stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not os.path.exists(os.path.join(out, "particles_000020.h5")) and time.monotonic() < deadline:
        time.sleep(0.05)
    expect("a second run while the first writes", run(program, scene, out), 2, "a run is still writing there",
           f"mpm-solid, pid {first.pid}, started")
    first.send_signal(signal.SIGKILL)
    first.wait()
    expect("a rerun after kill -9", run(program, scene, out), 2, "holds the output of an earlier run",
           f"pid {first.pid}", "pass --overwrite")
    expect("a rerun with --overwrite", run(program, scene, out, "--overwrite"), 0)
    snapshots = sorted(n for n in os.listdir(out) if n.startswith("particles_"))
    print(f"after the rerun: {len(snapshots)} snapshots")
    if len(snapshots) != 11:  # the scene's end_time / interval + the initial one
        failures.append(f"{len(snapshots)} snapshots after --overwrite, expected the rerun's 11 alone")

    # The manifest lists every file the run wrote, each once.
    with open(os.path.join(out, ".run.manifest")) as f:
        manifest = [line.strip() for line in f if not line.startswith("#")]
    written = sorted(n for n in os.listdir(out) if not n.startswith(".run."))
    print(f"the manifest lists {len(manifest)} files, the folder holds {len(written)}")
    if sorted(manifest) != written:
        failures.append(f"the manifest lists {sorted(set(manifest) ^ set(written))} unlike the folder")

    # A user's files: one like a run's output, one not.
    mine, notes = os.path.join(out, "my_survey_data.h5"), os.path.join(out, "notes.txt")
    for path in (mine, notes):
        with open(path, "w") as f:
            f.write("mine\n")
    expect("--overwrite beside a file no run listed", run(program, scene, out, "--overwrite"), 2,
           "--overwrite removes only the files the earlier run listed",
           "my_survey_data.h5 looks like a run's output, but no run listed it in .run.manifest")
    expect("a run beside it", run(program, scene, out), 2, "holds the output of an earlier run")
    if not os.path.exists(mine):
        failures.append("my_survey_data.h5 was removed")
    lonely = os.path.join(work, "lonely")
    os.makedirs(lonely)
    shutil.copy(mine, lonely)
    expect("a run into a folder holding only a file no run listed", run(program, scene, lonely), 2,
           "my_survey_data.h5 looks like a run's output, but no run listed it", "move it, or choose another folder")
    os.remove(mine)
    expect("--overwrite once it is gone", run(program, scene, out, "--overwrite"), 0)
    if not os.path.exists(notes):
        failures.append("--overwrite removed notes.txt, which looks like no run's output")

    # The folder removed while the run writes there.
    gone = os.path.join(work, "gone")
    second = subprocess.Popen([program, scene, "-q", "-o", gone, "--set", 'scene.end_time="10 s"', "--set",
                               'output.interval="0.001 s"'], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not os.path.exists(os.path.join(gone, "particles_000003.h5")) and time.monotonic() < deadline:
        time.sleep(0.02)
    # Gone at once (a removal file by file would leave the folder there for
    # a while, and the message would rightly say how much its disk holds).
    os.rename(gone, gone + "_moved")
    while os.path.exists(gone + "_moved"):  # the run may write a file in it as it goes
        shutil.rmtree(gone + "_moved", ignore_errors=True)
    _, stderr = second.communicate(timeout=60)
    last = stderr.strip().splitlines()[-1] if stderr.strip() else ""
    expect("the folder removed mid-run", (second.returncode, last), 1, f"the folder {gone} no longer exists")
    if "MB free" in last or "filesystem error" in last:
        failures.append(f"the folder removed mid-run: '{last}'")

    a_file = os.path.join(work, "a_file")
    open(a_file, "w").close()
    expect("-o naming a file", run(program, scene, a_file), 2, "it exists and is not a folder")
    if failures:
        sys.exit("; ".join(failures))


if __name__ == "__main__":
    main()
