"""A study measure: the gas pressure field at the run's last output, compared
node by node with the reference run's (cases.study: RMS difference over the
reference's largest |p|). For comparing coupling schemes and windows on one
seepage mesh."""
from .run_output import seepage_state


def quantities(run_dir):
    return {"pressure": seepage_state(run_dir)[2]}
