"""The outburst's headline quantities for cases.study (no analytic
solution: the study compares them with a much finer reference run): the peak
ejection speed at the face centre, the farthest coal from the face, the gas
released into the tunnel and the fully damaged share of the coal."""
from .headline import headline


def quantities(run_dir):
    h = headline(run_dir)
    return {"centre_speed": h["centre_m_per_s"], "farthest": h["farthest_m"],
            "gas_released": h["gas_released_m3_per_m"], "fully_damaged": h["fully_damaged_fraction"]}
