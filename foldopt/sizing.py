"""Panel sizing.

The flat-area equivalent of a design (Shin et al. Sec. VII: "we need about 2.61x larger PV panel
to achieve the same t_solar with the flat panel") is the factor k by which a flat panel's area
must grow for its ``t_solar`` to match. It assumes power proportional to area, as for the ideal
model and for panels grown by adding identical cells. Since ``t_solar(k P, L) = t_solar(P, L/k)``,
k follows from one root search for the load.
"""

from __future__ import annotations

from foldopt.metrics import load_for_t_solar


def flat_area_multiple(p_flat, p_load, target_t_solar, step_hours):
    """Factor by which the flat panel's area must grow to reach ``target_t_solar``.

    Parameters
    ----------
    p_flat : array_like
        The flat panel's power over the day [W], 1-D.
    p_load : float
        [W].
    target_t_solar : float
        [h].
    step_hours : float
        [h].

    Returns
    -------
    float
        Area multiple [-]; NaN if no flat panel of any size reaches the target (longer than the
        flat panel's daylight).
    """
    return p_load / load_for_t_solar(p_flat, target_t_solar, step_hours)
