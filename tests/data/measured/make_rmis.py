"""Write rmis_2019-02.csv and rmis_2022-01.csv, foldopt's generic measured CSV, from the two RMIS
files the pvanalytics 0.2.2 wheel ships (pvanalytics/data/irradiance_RMIS_NREL.csv and
rmis_weather_data.csv: NREL's Research Measurement and Irradiance System, Golden, Colorado, 5-min
averages). Their stamps are Mountain Standard Time without an offset (the first file's own
pvlib_zenith column is pvlib's zenith at the stamps on UTC-07:00 at 39.7406 N, 105.1774 W, 1829 m,
to 0.0001 deg) and end their 5 minutes, as NREL's measurement stations stamp averages.

Run: python make_rmis.py DIR, DIR holding the wheel's pvanalytics/data.
"""

import sys
from pathlib import Path

import pandas as pd

data = Path(sys.argv[1]) / "pvanalytics" / "data"
here = Path(__file__).parent
irradiance = pd.read_csv(data / "irradiance_RMIS_NREL.csv", index_col=0, parse_dates=True)
weather = pd.read_csv(data / "rmis_weather_data.csv", index_col=0, parse_dates=True)
for frame, columns, name in (
        (irradiance, {"irradiance_ghi__7981": "ghi", "irradiance_dni__7982": "dni", "irradiance_dhi__7983": "dhi"},
         "rmis_2019-02.csv"),
        (weather, {"Global Horizontal": "ghi", "Direct Normal": "dni", "Diffuse Horizontal": "dhi",
                   "Ambient Temperature": "temp_air", "Wind Speed": "wind_speed"}, "rmis_2022-01.csv")):
    out = frame[list(columns)].rename(columns=columns).round(2)
    out.index = out.index.tz_localize("Etc/GMT+7").strftime("%Y-%m-%dT%H:%M:%S-07:00")
    out.index.name = "timestamp"
    out.to_csv(here / name)
