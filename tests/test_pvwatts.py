"""An independent reference for a real year: NREL's PVWatts v8 (through nrel-pysam) on the same
TMY3 file gives the same annual plane-of-array gain of the ideal dual-axis tracker over the fixed
panel at latitude tilt, within 0.5 percentage point."""

import datetime as dt
from pathlib import Path

import numpy as np
import pvlib
import pytest

from foldopt.engine import evaluation as engine
from foldopt.inputs.plan import make_plan
from foldopt.engine.sky import build_sky
from foldopt.studies.engine_options import engine_options
from foldopt.studies.designs import sky_tracker_orientation

pvwatts = pytest.importorskip("PySAM.Pvwattsv8", reason="nrel-pysam is a test dependency ('.[test]')")
TMY3 = Path(pvlib.__file__).parent / "data" / "723170TYA.CSV"
TILT = 36.1  # the file's latitude
FIXED, TWO_AXIS = 0, 4  # PVWatts array types


def pvwatts_poa(array_type):
    """PVWatts' hourly plane-of-array irradiance [W/m^2] (its ``poa``: incident, before the cover),
    its rows as far apart as it allows (ground coverage ratio 0.01), the fixed albedo 0.2."""
    model = pvwatts.default("PVWattsNone")
    model.SolarResource.solar_resource_file = str(TMY3)
    model.SolarResource.use_wf_albedo = 0
    model.SolarResource.albedo = (0.2,) * 12
    model.SystemDesign.array_type = array_type
    model.SystemDesign.tilt, model.SystemDesign.azimuth, model.SystemDesign.gcr = TILT, 180.0, 0.01
    model.SystemDesign.system_capacity = 1.0
    model.execute()
    return np.asarray(model.Outputs.poa).reshape(365, 24), np.asarray(model.Outputs.sunup).reshape(365, 24)


def test_tracker_gain_on_the_plane_of_array_is_pvwatts():
    study = make_plan({"name": "pvwatts", "weather": str(TMY3), "panel": {"area": 1.0, "tilt": TILT, "azimuth": 180},
                       "p_load": 1.0, "albedo": 0.2, "transposition": "perez"}).base
    year = [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(365)]
    sky = build_sky(engine_options(study).sky, [study.site] * 365, year)
    tilt, azimuth, normal = sky_tracker_orientation(sky, study, "dual-axis")
    hourly = {  # foldopt's minutes, hour by hour [W/m^2]
        "fixed": engine.poa(sky, np.full((365, 1), TILT), np.full((365, 1), 180.0), incident=True),
        "tracker": engine.poa(sky, tilt, azimuth, incident=True, normal=normal),
    }
    hourly = {name: poa.reshape(365, 24, 60).mean(axis=-1) for name, poa in hourly.items()}
    (fixed, sunup), (tracker, _) = pvwatts_poa(FIXED), pvwatts_poa(TWO_AXIS)
    ours = hourly["tracker"].sum() / hourly["fixed"].sum() - 1
    theirs = tracker.sum() / fixed.sum() - 1
    # Measured: foldopt 29.49 %, PVWatts 29.85 %. Where they differ:
    # - hours of full sun (PVWatts' sunup == 1): foldopt's fixed panel 0.1 % above PVWatts and its
    #   tracker 0.1 % below, 0.25 point of the gain. foldopt applies pvlib's Perez (1990) to each
    #   minute of light spread along the clear sky, and Perez is not linear in its inputs (the sky's
    #   clearness and brightness of a minute are not those of the hour); PVWatts applies its own
    #   Perez to the hour;
    # - the hours of sunrise and sunset: PVWatts puts the whole hour's light at the sun's position
    #   halfway through the hour's sunlit part; foldopt spreads it minute by minute along the clear
    #   sky, where a tracker facing the rising sun gets less of the Perez circumsolar term: 2 of
    #   PVWatts' 31 kWh/m^2 there, 0.1 point of the gain;
    # - not glass: both are the irradiance incident on the plane (PVWatts' "poa", before its cover
    #   loss "tpoa"; foldopt's with no incidence-angle modifier).
    assert ours * 100 == pytest.approx(theirs * 100, abs=0.5)
    full_sun = sunup == 1
    for name, theirs_hours in (("fixed", fixed), ("tracker", tracker)):
        assert hourly[name][full_sun].sum() == pytest.approx(theirs_hours[full_sun].sum(), rel=0.003), name
    assert hourly["fixed"].sum() / 1000 == pytest.approx(fixed.sum() / 1000, rel=0.002)  # 1776 vs 1775 kWh/m^2
