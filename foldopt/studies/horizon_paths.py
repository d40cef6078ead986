"""The sun's paths over a site's horizon on a study's days: what ``horizon_sun_paths.png`` draws
and what the answer says of the light the horizon takes.

The module may import numpy, pandas, pvlib, :mod:`foldopt.inputs` and :mod:`foldopt.physics`.
"""

from __future__ import annotations

import datetime as dt

import numpy as np

from foldopt.inputs.sections import parse_timezone
from foldopt.physics.horizon import horizon_elevation_at

#: Step of the drawn paths [min].
PATH_STEP_MIN = 10
#: At most this many days are drawn, evenly spaced over the study's.
MAX_DAYS = 60
#: At most this many days are counted in the hidden share (evenly spaced over the study's).
MAX_COUNTED_DAYS = 400


def sun_paths(study, dates) -> dict | None:
    """The sun's azimuth and apparent elevation through each day, and the site's horizon line.

    Parameters
    ----------
    study : foldopt.Study
        Its site (and horizon).
    dates : sequence of datetime.date or str
        The study's days.

    Returns
    -------
    dict or None
        ``dates`` (list of str), ``azimuth`` and ``elevation`` (n_days, n_steps) [deg] of the sun
        (NaN below the horizontal), ``horizon_azimuth`` and ``horizon_elevation`` [deg], and
        ``hidden_pct``: the share of the study's daylight (sun above the horizontal) with the sun
        behind the horizon line [%], over all its days (at most :data:`MAX_COUNTED_DAYS`, evenly
        spaced); None for a site without a horizon.
    """
    site = study.site
    if site.horizon is None:
        return None
    import pandas as pd

    days = sorted({dt.date.fromisoformat(str(day)[:10]) for day in dates})
    days = [days[i] for i in _spread(len(days), MAX_COUNTED_DAYS)]
    zone = parse_timezone(site.timezone)
    steps = np.arange(0, 1440, PATH_STEP_MIN)
    start = pd.DatetimeIndex([dt.datetime.combine(day, dt.time(), zone) for day in days])
    times = pd.DatetimeIndex(
        (
            start.tz_convert(None).to_numpy()[:, None] + steps[None, :].astype("timedelta64[m]")
        ).ravel(),
        tz="UTC",
    )
    import pvlib

    position = pvlib.solarposition.get_solarposition(
        times, site.latitude, site.longitude, site.altitude
    )
    azimuth = position["azimuth"].to_numpy().reshape(len(days), steps.size)
    elevation = position["apparent_elevation"].to_numpy().reshape(len(days), steps.size)
    horizon_azimuth, horizon_elevation = site.horizon.profile()
    up = elevation > 0
    hidden = up & (elevation <= horizon_elevation_at(azimuth, horizon_azimuth, horizon_elevation))
    drawn = _spread(len(days), MAX_DAYS)
    return {
        "dates": [days[i].isoformat() for i in drawn],
        "azimuth": np.where(up, azimuth, np.nan)[drawn],
        "elevation": np.where(up, elevation, np.nan)[drawn],
        "horizon_azimuth": horizon_azimuth,
        "horizon_elevation": horizon_elevation,
        "hidden_pct": float(100.0 * hidden.sum() / max(up.sum(), 1)),
    }


def _spread(count: int, most: int) -> list[int]:
    """At most ``most`` indices evenly spread over ``range(count)``, the first and last among them."""
    return [int(i) for i in np.unique(np.linspace(0, count - 1, min(count, most)).round())]


def horizon_notes(study, dates) -> list[dict]:
    """The answer's note on the horizon: how much of the days' sun it hides.

    Parameters
    ----------
    study : foldopt.Study
    dates : sequence of datetime.date or str

    Returns
    -------
    list of dict
        One note concerning every design, or none without a horizon.
    """
    paths = sun_paths(study, dates)
    if paths is None:
        return []
    return [
        {
            "note": f"the horizon hides the sun for {paths['hidden_pct']:.1f} % of the days' daylight "
            "(beam and circumsolar light blocked then; the sky diffuse reduced per sub-panel)",
            "designs": [],
        }
    ]
