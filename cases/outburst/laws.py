"""The outburst scene under another tensile damage law, and its seam meshed at
another element size: outburst.toml keeps the paper's local law (an ultimate
strain ratio); a crack band replaces that line with a fracture energy. The
scene's one relative path, its seepage mesh, is made absolute, so the copy may
live in a study's folder."""
import os
import subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
SHIPPED = os.path.join(HERE, "outburst.toml")
LOCAL_LINE = "ultimate_strain_ratio = 5"
MESH_LINE = 'file = "seam.msh"'

# G_f = K_Ic^2 / E, E = 6 GPa (Table 1), with the fracture toughness of coal in
# semi-circular bend tests (issue 17): about 0.12 MPa m^0.5 for outburst-prone
# coal and 0.31 for coal that does not burst.
FRACTURE_ENERGY = {"outburst-prone": "2.4 J/m2", "non-outburst": "16 J/m2"}


def crack_band_scene(folder, fracture_energy=FRACTURE_ENERGY["outburst-prone"]):
    """outburst.toml with a crack band of the given G_f, written into folder; its path."""
    with open(SHIPPED) as f:
        text = f.read()
    lines = text.splitlines(keepends=True)
    for start in (LOCAL_LINE, MESH_LINE):
        if sum(line.startswith(start) for line in lines) != 1:
            raise SystemExit(f"{SHIPPED} no longer has one line starting '{start}' to replace")
    # Whole lines, their comments with them: the local law's says where eta comes from.
    replaced = {LOCAL_LINE: f'fracture_energy = "{fracture_energy}"  # crack band (cases/outburst/laws.py)\n',
                MESH_LINE: f'file = "{os.path.join(HERE, "seam.msh")}"\n'}
    text = "".join(next((new for start, new in replaced.items() if line.startswith(start)), line) for line in lines)
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, f"outburst_crack_band_{fracture_energy.split()[0]}.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def seam_mesh(folder, h, name):
    """The seam meshed by Gmsh with elements of edge h [m] (seam.geo takes h) as
    folder/name, unless it is there already; its absolute path."""
    path = os.path.abspath(os.path.join(folder, name))
    if not os.path.exists(path):
        subprocess.run(["gmsh", "-2", "-format", "msh41", "-setnumber", "h", repr(float(h)),
                        os.path.join(HERE, "seam.geo"), "-o", path], check=True, stdout=subprocess.DEVNULL)
    return path
