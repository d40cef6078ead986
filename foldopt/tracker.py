"""Sun trackers.

Only the ideal dual-axis tracker is modelled so far: its normal follows the sun exactly, so the
beam on the panel equals the direct normal irradiance whenever the sun is up (Shin et al.
Sec. IV-A, Fig. 4, the "ideal case" the twofold panel is compared against).
"""

from __future__ import annotations

import numpy as np

TRACKERS = ("dual-axis",)


def tracker_incidence_factor(solar_zenith, model="dual-axis"):
    """Beam incidence factor of a tracked panel [-].

    Parameters
    ----------
    solar_zenith : array_like
        Solar zenith [deg].
    model : {'dual-axis'}
        Tracker model; ``dual-axis`` is ideal: 1 with the sun above the horizon, else 0.
    """
    if model == "dual-axis":
        return np.where(np.asarray(solar_zenith, dtype=float) < 90.0, 1.0, 0.0)
    raise ValueError(f"tracker must be one of {', '.join(TRACKERS)}; got {model!r}")
