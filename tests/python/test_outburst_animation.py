"""The main job's film (cases.outburst.animate) of a short run of the shipped
case: one frame per particle snapshot, as H.264 (counted by ffprobe) and as
a GIF (counted by Pillow), and a clear refusal of another format."""
import glob
import os
import shutil
import subprocess
import sys

import pytest
from PIL import Image


def film(repo, run, path):
    return subprocess.run([sys.executable, "-m", "cases.outburst.animate", run, "--output", str(path)],
                          capture_output=True, text=True, cwd=repo, timeout=600)


def snapshots(run):
    return len(glob.glob(os.path.join(run, "particles_*.h5")))


@pytest.mark.skipif(shutil.which("ffprobe") is None, reason="no ffprobe (scripts/install-deps.sh installs ffmpeg)")
def test_mp4_has_a_frame_per_snapshot(repo, outburst_run, tmp_path):
    done = film(repo, outburst_run, tmp_path / "outburst.mp4")
    assert done.returncode == 0, done.stderr
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                            "stream=nb_read_frames,codec_name,width,height", "-of", "default=noprint_wrappers=1",
                            str(tmp_path / "outburst.mp4")], capture_output=True, text=True, check=True)
    fields = dict(line.split("=", 1) for line in probe.stdout.split())
    print(fields, "snapshots:", snapshots(outburst_run))
    assert fields["codec_name"] == "h264"
    assert int(fields["width"]) % 2 == 0 and int(fields["height"]) % 2 == 0
    assert int(fields["nb_read_frames"]) == snapshots(outburst_run) >= 2


def test_gif_has_a_frame_per_snapshot(repo, outburst_run, tmp_path):
    done = film(repo, outburst_run, tmp_path / "outburst.gif")
    assert done.returncode == 0, done.stderr
    with Image.open(tmp_path / "outburst.gif") as gif:
        print("frames:", gif.n_frames, "snapshots:", snapshots(outburst_run))
        assert gif.n_frames == snapshots(outburst_run) >= 2


def test_another_format_is_refused(repo, outburst_run, tmp_path):
    done = film(repo, outburst_run, tmp_path / "outburst.avi")
    assert done.returncode == 1
    assert "write an .mp4 or a .gif" in done.stderr
    assert not (tmp_path / "outburst.avi").exists()
