"""--explain prints the keys a scene uses and stops: it runs nothing and
writes no output folder; --format json prints one JSON object whose choice
keys list their words."""
import json
import os
import subprocess


def test_explain_prints_json_and_runs_nothing(repo, build, tmp_path):
    out = tmp_path / "never"
    for program, scene in [("mpm_solid/mpm-solid", "elastic_block/elastic_block.toml"),
                           ("seepage_fe/seepage-fe", "drainage/drainage.toml"),
                           ("seepage_fe/seepage-fe", "drainage_3d/drainage_3d.toml"),
                           ("coupler/outburst", "gas_face/gas_face.toml")]:
        done = subprocess.run([os.path.join(build, program), os.path.join(repo, "cases", scene), "-o", str(out),
                               "--explain", "--format", "json"], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        assert not out.exists(), f"{program} --explain wrote {out}"
        keys = {k["key"]: k for k in json.loads(done.stdout)["keys"]}
        assert keys and all(k["expects"] for k in keys.values())
        choices = [k for k in keys.values() if k["expects"] == "one of"]
        assert choices and all(len(k["choices"]) >= 2 for k in choices)


def test_explain_gives_a_box_three_of_each(repo, build):
    """A 3D scene's vectors, as read: three entries each, the default origin too."""
    done = subprocess.run([os.path.join(build, "seepage_fe/seepage-fe"),
                           os.path.join(repo, "cases/drainage_3d/drainage_3d.toml"), "--explain", "--format", "json"],
                          capture_output=True, text=True, timeout=60, check=True)
    keys = {k["key"]: k for k in json.loads(done.stdout)["keys"]}
    assert keys["seepage.mesh.type"]["value"] == '"box"'
    assert keys["seepage.mesh.origin"]["default"] and keys["seepage.mesh.origin"]["value"] == '["0 m", "0 m", "0 m"]'
    for key in ["seepage.mesh.size", "seepage.mesh.cells", "seepage.mesh.grading", "seepage.regions[1].box_min",
                "seepage.regions[1].box_max"]:
        assert keys[key]["value"].count(",") == 2, keys[key]
    assert "back, front" in keys["seepage.boundaries[0].name"]["doc"]


def test_format_needs_explain(repo, build):
    done = subprocess.run([os.path.join(build, "mpm_solid/mpm-solid"),
                           os.path.join(repo, "cases/elastic_block/elastic_block.toml"), "--format", "json"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "--explain" in done.stderr
