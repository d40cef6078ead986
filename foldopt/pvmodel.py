"""Power of one (sub-)panel at its maximum power point.

Only the ``ideal`` model exists so far: P = efficiency * area * irradiance, with a constant
efficiency (foldopt SPEC, "PV electrical model"). I-V based models plug in here by name.
"""

from __future__ import annotations

import numpy as np

PV_MODELS = ("ideal",)


def max_power(poa_global, area, efficiency, model="ideal"):
    """Maximum power of a panel [W].

    Parameters
    ----------
    poa_global : array_like
        Irradiance on the panel [W/m^2].
    area : float
        Panel area [m^2].
    efficiency : float
        Conversion efficiency [-], for ``ideal``.
    model : {'ideal'}
        PV model.
    """
    if model == "ideal":
        return efficiency * area * np.asarray(poa_global, dtype=float)
    raise ValueError(f"pv_model must be one of {', '.join(PV_MODELS)}; got {model!r}")
