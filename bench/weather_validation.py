"""Measured minutes against their hourly means, on the measured days committed in tests/data/measured:
the manual's validation table (docs/weather.rst).

    python bench/weather_validation.py            # prints the reStructuredText table and the biases
    python bench/weather_validation.py --write    # and writes it into the manual (docs/weather_validation.inc)

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
#: A day is broken cloud where its measured GHI varies within its hours (the mean over lit hours of
#: the within-hour standard deviation) more than the smooth path's by this ratio and this much
#: [W/m^2]: clouds that pass within the hours, not the clear sky's own curve.
BROKEN_RATIO, BROKEN_EXCESS_W_M2 = 1.25, 8.0


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
        measured, smooth = table["within_hour_sd_measured_w_m2"], table["within_hour_sd_smooth_w_m2"]
        broken = (measured > BROKEN_RATIO * smooth) & (measured - smooth > BROKEN_EXCESS_W_M2)
        frames.append(table.assign(file=name, sky=np.where(broken, "broken", "steady")))
    return pd.concat(frames, ignore_index=True)


def rst(table: pd.DataFrame) -> str:
    """The table of the manual: a row per day and load, the twofold panel and the tracker, and the
    summary per sky."""
    def cell(row) -> str:
        inside = row.ensemble_p5_h - 1e-9 <= row.measured_h <= row.ensemble_p95_h + 1e-9
        return (f"{row.measured_h:.2f} / {row.smooth_h:.2f} ({60 * (row.smooth_h - row.measured_h):+.0f} min) / "
                f"{row.ensemble_p5_h:.2f}-{row.ensemble_p95_h:.2f}{'' if inside else ' (out)'}")

    lines = [".. list-table:: t_solar [h]: measured / smooth (its bias) / ensemble P5-P95", "   :header-rows: 1",
             "", "   * - file, day", "     - sky", "     - load", "     - twofold", "     - tracker"]
    for (file, date, load), rows in table.groupby(["file", "date", "p_load_w"], sort=False):
        by = {row.design: row for row in rows.itertuples()}
        lines += [f"   * - {file}, {date}", f"     - {by['twofold'].sky}", f"     - {load:g} W",
                  f"     - {cell(by['twofold'])}", f"     - {cell(by['tracker'])}"]
    summary = summarise(table)
    lines += ["", ".. list-table:: Over every design and load", "   :header-rows: 1", "",
              "   * - sky", "     - cases", "     - smooth path: mean bias", "     - mean absolute bias",
              "     - ensemble P5-P95 contains the measured", "     - mean width of P5-P95"]
    for sky, row in summary.iterrows():
        lines += [f"   * - {sky}", f"     - {row.cases:.0f}", f"     - {row.smooth_bias_min:+.1f} min",
                  f"     - {row.smooth_abs_bias_min:.1f} min", f"     - {100 * row.ensemble_contains:.0f} %",
                  f"     - {row.width_min:.1f} min"]
    return "\n".join(lines) + "\n"


def summarise(table: pd.DataFrame) -> pd.DataFrame:
    """Per sky: the cases, the smooth path's mean and mean absolute bias [min], the share of cases
    the ensemble's P5-P95 contains and its mean width [min]."""
    table = table.assign(
        inside=(table["ensemble_p5_h"] - 1e-9 <= table["measured_h"]) & (table["measured_h"] <= table[
            "ensemble_p95_h"] + 1e-9),
        bias=60 * (table["smooth_h"] - table["measured_h"]),
        width=60 * (table["ensemble_p95_h"] - table["ensemble_p5_h"]))
    return table.groupby("sky").agg(cases=("inside", "size"), ensemble_contains=("inside", "mean"),
                                    smooth_bias_min=("bias", "mean"),
                                    smooth_abs_bias_min=("bias", lambda b: b.abs().mean()),
                                    width_min=("width", "mean"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--members", type=int, default=20)
    parser.add_argument("--write", action="store_true", help="also write docs/weather_validation.inc")
    args = parser.parse_args()
    text = rst(validation(args.members))
    print(text)
    if args.write:
        (Path(__file__).resolve().parents[1] / "docs" / "weather_validation.inc").write_text(text)


if __name__ == "__main__":
    main()
