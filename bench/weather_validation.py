"""Measured minutes against their hourly means, on the measured days committed in tests/data/measured:
the manual's validation table (docs/weather.rst).

    python bench/weather_validation.py            # prints the reStructuredText table and the biases
    python bench/weather_validation.py --members 40

For each day of each file (:func:`foldopt.studies.validation.minute_validation`): t_solar of the
flat panel, the twofold panel at its best fold angle and the tracker (the A-300 single-diode
sub-panels, Perez diffuse light, a 0.108 m^2 panel that peaks near 20 W), at loads of 1, 2, 4 and
8 W, from the measured steps, from the day's hourly means through the smooth path, and through a
cloud ensemble of ``--members`` members (P5 to P95). Then, per sky, the mean bias of the smooth path
[min] and the share of cases the ensemble's P5-P95 contains.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from foldopt.inputs.plan import make_plan
from foldopt.studies.validation import minute_validation

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "measured"
#: The files, their format and the site where the file holds none (solarstations.org's, as the
#: tests take them).
FILES = {
    "SURFRAD Alamosa": ({"path": "surfrad-slv16001.dat", "format": "surfrad"}, None),
    "MIDC NWTC M2": ({"path": "midc_20181014.txt", "format": "midc"},
                     {"name": "NWTC M2", "latitude": 39.9106, "longitude": -105.2347, "altitude": 1855.0}),
    "MIDC UA OASIS": ({"path": "midc_raw_20181018.txt", "format": "midc"},
                      {"name": "UA OASIS", "latitude": 32.22969, "longitude": -110.95534, "altitude": 786.0}),
    "SRML Eugene": ({"path": "SRML-day-EUPO1801.txt", "format": "srml"},
                    {"name": "Eugene", "latitude": 44.0468, "longitude": -123.0742, "altitude": 150.0}),
    "RMIS Golden 2019": ({"path": "rmis_2019-02.csv", "format": "csv"},
                         {"name": "NREL RMIS", "latitude": 39.7406, "longitude": -105.1774, "altitude": 1829.0}),
    "RMIS Golden 2022": ({"path": "rmis_2022-01.csv", "format": "csv"},
                         {"name": "NREL RMIS", "latitude": 39.7406, "longitude": -105.1774, "altitude": 1829.0}),
}
LOADS = (1.0, 2.0, 4.0, 8.0)
#: A day is broken cloud where its measured GHI varies within its hours by more than this [W/m^2]
#: (the mean over lit hours of the within-hour standard deviation) above the smooth path's.
BROKEN_EXCESS_W_M2 = 15.0


def study_of(weather: dict, site: dict | None):
    data = {"name": "validation", "weather": {**weather, "path": str(DATA / weather["path"])},
            "panel": {"area": 0.108}, "p_load": 2.0, "pv_model": "single-diode", "transposition": "perez",
            "fold_angles": {"start": 5, "stop": 180, "step": 5}}
    if site is not None:
        data["site"] = site
    return make_plan(data).base


def validation(members: int = 20, seed: int = 0) -> pd.DataFrame:
    """Every file's :func:`minute_validation`, with its ``file`` and the day's ``sky``."""
    frames = []
    for name, (weather, site) in FILES.items():
        table = minute_validation(study_of(weather, site), LOADS, members, seed)
        excess = table["within_hour_sd_measured_w_m2"] - table["within_hour_sd_smooth_w_m2"]
        frames.append(table.assign(file=name, sky=np.where(excess > BROKEN_EXCESS_W_M2, "broken", "steady")))
    return pd.concat(frames, ignore_index=True)


def rst(table: pd.DataFrame) -> str:
    lines = [".. list-table::", "   :header-rows: 1", "", "   * - file, day", "     - sky", "     - load",
             "     - design", "     - measured", "     - smooth", "     - ensemble P5-P95"]
    for row in table.itertuples():
        inside = row.ensemble_p5_h - 1e-9 <= row.measured_h <= row.ensemble_p95_h + 1e-9
        lines += [f"   * - {row.file}, {row.date}", f"     - {row.sky}", f"     - {row.p_load_w:g} W",
                  f"     - {row.design}", f"     - {row.measured_h:.2f} h",
                  f"     - {row.smooth_h:.2f} h ({60 * (row.smooth_h - row.measured_h):+.0f} min)",
                  f"     - {row.ensemble_p5_h:.2f}-{row.ensemble_p95_h:.2f} h{'' if inside else ' (out)'}"]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--members", type=int, default=20)
    args = parser.parse_args()
    table = validation(args.members)
    print(rst(table))
    print()
    table["inside"] = (table["ensemble_p5_h"] - 1e-9 <= table["measured_h"]) & (
        table["measured_h"] <= table["ensemble_p95_h"] + 1e-9)
    table["smooth_bias_min"] = 60 * (table["smooth_h"] - table["measured_h"])
    summary = table.groupby("sky").agg(cases=("inside", "size"), ensemble_contains=("inside", "mean"),
                                       smooth_bias_min=("smooth_bias_min", "mean"),
                                       smooth_abs_bias_min=("smooth_bias_min", lambda b: b.abs().mean()))
    print(summary.round(2).to_string())


if __name__ == "__main__":
    main()
