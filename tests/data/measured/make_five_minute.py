"""Write five_minute.csv: the 1-min MIDC UA OASIS day of midc_raw_20181018.txt averaged to 5 minutes.

foldopt's generic measured CSV (foldopt.inputs.weather.stations): ISO 8601 stamps with their UTC
offset, each the end of its 5 minutes (like the MIDC file's own 1-min stamps), and the means of
the five 1-min values whose intervals make it up. Only whole 5-min intervals are written: the
file's first row (the minute ending at 00:00, the day before's) and its last four (whose interval
ends at 24:00) make no whole one, so the day's last 5 minutes are missing in the CSV. MIDC's
missing-value marker (-7999) stays out of the means. Run from anywhere:
``python tests/data/measured/make_five_minute.py``.
"""

from pathlib import Path

import pvlib

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "midc_raw_20181018.txt"
TARGET = HERE / "five_minute.csv"
COLUMNS = {"Global Horiz (platform) [W/m^2]": "ghi", "Direct Normal [W/m^2]": "dni", "Diffuse Horiz [W/m^2]": "dhi",
           "Air Temperature [deg C]": "temp_air", "Avg Wind Speed @ 3m [m/s]": "wind_speed"}


def main() -> None:
    data = pvlib.iotools.read_midc(SOURCE, raw_data=True)[list(COLUMNS)].rename(columns=COLUMNS)
    data = data.where(data > -7999.0)
    # Each 1-min stamp ends its minute: a 5-min interval ending at t holds the stamps in (t - 5 min, t].
    groups = data.resample("5min", closed="right", label="right")
    means, counts = groups.mean(), groups.count().min(axis=1)
    means = means[counts == 5]
    out = means.round({"ghi": 1, "dni": 1, "dhi": 1, "temp_air": 2, "wind_speed": 3})
    out.index = [stamp.isoformat() for stamp in out.index]  # MST: a fixed UTC-07:00
    out.index.name = "timestamp"
    with open(TARGET, "w", newline="") as file:
        file.write("# NREL MIDC UA OASIS (site UAT), 2018-10-18, 5-minute means of the 1-minute values of\n"
                   "# midc_raw_20181018.txt (pvlib-python tests/data), made by make_five_minute.py.\n"
                   "# Stamps mark the end of each 5 minutes; W/m^2, C, m/s.\n")
        out.to_csv(file, lineterminator="\n")


if __name__ == "__main__":
    main()
