"""The stand-in program's error is its result itself."""
import os


def errors(run_dir):
    with open(os.path.join(run_dir, "result.txt")) as f:
        return {"value": float(f.read())}
