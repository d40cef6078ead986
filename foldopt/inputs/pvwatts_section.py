"""The ``pvwatts`` section of a study: the PVWatts model's rating, temperature coefficient and
system losses (:class:`PVWatts`), read by ``pv_model: pvwatts``. Like the other sections it only
validates; the power is :meth:`foldopt.physics.pvmodel.PVModel.max_power`'s.

The defaults are those a designer of one small panel would choose, each with its source
(:data:`LOSSES`): PVWatts' own figures [1]_ where they describe a small panel, none where they
describe what foldopt models itself or what does not lower a panel's power.

The module may import pydantic and :mod:`foldopt.inputs.fields`.

References
----------
.. [1] A. P. Dobos, "PVWatts Version 5 Manual", NREL/TP-6A20-62641, 2014, Table 2 (default
   system losses) and Eq. 1 to 3; pvlib.pvsystem.pvwatts_losses holds the same defaults.
.. [2] NREL, SAM Simulation Core, ``ssc/cmod_pvwattsv8.cpp`` (PVWatts Version 8), module types:
   standard -0.0037 /C (premium -0.0035, thin film -0.0032); the standard (crystalline-silicon)
   module is what a small panel is made of.
"""

from __future__ import annotations

from pydantic import Field

from foldopt.inputs.fields import StrictModel, interval

#: Each system loss [%] where a study gives none, with why (sources in the module's References).
LOSSES = {
    # [1]: dust and dirt on the cover, PVWatts' default for an array cleaned by rain.
    "soiling": 2.0,
    # PVWatts' 3 % stands for rows and nearby objects shading an array; foldopt casts the site's
    # horizon on each sub-panel itself (``horizon``), and one panel has no rows.
    "shading": 0.0,
    # [1]: PVWatts' default; snow is a site's season, not a design's.
    "snow": 0.0,
    # [1]: modules' and cells' electrical differences within a string (the sub-panels' ratings
    # differ within their tolerance, as modules do).
    "mismatch": 2.0,
    # [1]: resistive loss in DC wiring, the 2 % voltage drop designers budget for.
    "wiring": 2.0,
    # [1]: resistive loss in connectors.
    "connections": 0.5,
    # [1]: light-induced degradation of crystalline silicon in its first months.
    "lid": 1.5,
    # [1]: the measured rating below the nameplate's, within the manufacturer's tolerance.
    "nameplate_rating": 1.0,
    # [1]: PVWatts' default, a new panel (degradation is a lifetime's, not a day's).
    "age": 0.0,
    # PVWatts' 3 % is the time a grid-tied system is down (grid outages, inverter repairs): it
    # lowers a year's energy, not the power a working panel gives, which t_solar counts.
    "availability": 0.0,
}
#: The temperature coefficient of power where a study gives none [1/C] ([2]).
GAMMA_PDC = -0.0037


def total_losses(losses: dict) -> float:
    """The system loss of PVWatts' breakdown: ``100 (1 - prod(1 - L_i / 100))`` [%] (Dobos 2014,
    Eq. 3; pvlib.pvsystem.pvwatts_losses).

    Parameters
    ----------
    losses : dict of str to float
        Each loss [%].

    Returns
    -------
    float
        [%].

    Examples
    --------
    >>> round(total_losses(LOSSES), 2)
    8.68
    """
    kept = 1.0
    for loss in losses.values():
        kept *= 1.0 - loss / 100.0
    return 100.0 * (1.0 - kept)


def _loss(name: str):
    return Field(LOSSES[name], description=f"[%]; default {LOSSES[name]:g}")


class PVWatts(StrictModel):
    """The PVWatts DC model's settings: ``P = pdc0 E / 1000 (1 + gamma_pdc (T_cell - 25 C)) (1 -
    losses)`` per sub-panel (:func:`pvlib.pvsystem.pvwatts_dc`, Dobos 2014 Eq. 1).

    Parameters
    ----------
    pdc0 : float, optional
        The whole panel's rating at 1000 W/m^2 and 25 C [W] in (0, 1e6]; default
        ``panel.efficiency x panel.area x 1000 W/m^2``. Each sub-panel has half of it.
    gamma_pdc : float
        Temperature coefficient of power [1/C] in [-0.01, 0.01]; default -0.0037.
    soiling, shading, snow, mismatch, wiring, connections, lid, nameplate_rating : float
        PVWatts' system losses [%], each in [0, 100); defaults in :data:`LOSSES`.
    age, availability : float
        As those.
    """

    pdc0: interval(0, 1e6, lo_open=True, unit=" W") | None = Field(
        None, description="the panel's rating [W]; default efficiency x area x 1000 W/m^2"
    )
    gamma_pdc: interval(-0.01, 0.01, unit=" 1/C") = Field(
        GAMMA_PDC, description=f"[1/C]; default {GAMMA_PDC:g}"
    )
    soiling: interval(0, 100, hi_open=True, unit=" %") = _loss("soiling")
    shading: interval(0, 100, hi_open=True, unit=" %") = _loss("shading")
    snow: interval(0, 100, hi_open=True, unit=" %") = _loss("snow")
    mismatch: interval(0, 100, hi_open=True, unit=" %") = _loss("mismatch")
    wiring: interval(0, 100, hi_open=True, unit=" %") = _loss("wiring")
    connections: interval(0, 100, hi_open=True, unit=" %") = _loss("connections")
    lid: interval(0, 100, hi_open=True, unit=" %") = _loss("lid")
    nameplate_rating: interval(0, 100, hi_open=True, unit=" %") = _loss("nameplate_rating")
    age: interval(0, 100, hi_open=True, unit=" %") = _loss("age")
    availability: interval(0, 100, hi_open=True, unit=" %") = _loss("availability")

    @property
    def losses(self) -> float:
        """The system loss [%] of the breakdown (:func:`total_losses`)."""
        return total_losses({name: getattr(self, name) for name in LOSSES})

    def efficiency(self, area: float, efficiency: float) -> float:
        """The efficiency [-] whose rating at 1000 W/m^2 is :attr:`pdc0` on ``area`` [m^2]; the
        panel's ``efficiency`` where no rating is given."""
        return efficiency if self.pdc0 is None else self.pdc0 / (1000.0 * area)
