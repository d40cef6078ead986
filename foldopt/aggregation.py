"""Deliverable power of the two sub-panels under each way of connecting them.

With the ``ideal`` PV model the sub-panels have no I-V curve, so both sit at their maximum
power point in any connection: ``parallel`` is the sum of the two maxima. Shin et al. Sec. V
describe the architectures; foldopt SPEC "Aggregating the two sub-panels" defines them:

- ``east``, ``west``: one sub-panel alone;
- ``parallel``: both on one converter;
- ``independent``: each on its own converter, the sum times a converter efficiency;
- ``switching``: per step the best of east / parallel / west (Shin et al. Sec. V-C, Fig. 8b).
"""

from __future__ import annotations

import numpy as np

CONNECTIONS = ("east", "west", "parallel", "independent", "switching")
SWITCH_STATES = ("east", "parallel", "west")


def connection_power(p_east, p_west, connection="switching", converter_efficiency=1.0):
    """Deliverable power of the pair [W] for one connection.

    Parameters
    ----------
    p_east, p_west : array_like
        Maximum power of each sub-panel [W].
    connection : {'east', 'west', 'parallel', 'independent', 'switching'}
    converter_efficiency : float, default 1
        Efficiency of each dedicated converter of ``independent`` [-].
    """
    p_east, p_west = np.asarray(p_east, dtype=float), np.asarray(p_west, dtype=float)
    if connection == "east":
        return p_east
    if connection == "west":
        return p_west
    if connection == "parallel":
        return p_east + p_west
    if connection == "independent":
        return converter_efficiency * (p_east + p_west)
    if connection == "switching":
        return np.max(np.stack([p_east, p_east + p_west, p_west]), axis=0)
    raise ValueError(f"connection must be one of {', '.join(CONNECTIONS)}; got {connection!r}")
