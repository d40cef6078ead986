"""The ``costs`` section of a study: what a device's parts cost, for the least-cost search of the
panel and buffer that meet the buffer's target (:mod:`foldopt.studies.least_cost`). Prices in US
dollars (USD); like the other sections it only validates (:mod:`foldopt.inputs.sections`).

Not :mod:`foldopt.inputs.costs`: that module holds Shin et al.'s constants of ``foldopt size``'s
panel sizing against grid energy (a panel cost and a grid price over a lifetime); this section is
a study's own prices of panel, buffer, hinge and tracker drive. The module may import pydantic and
:mod:`foldopt.names`.
"""

from __future__ import annotations

from pydantic import Field

from foldopt.inputs.fields import StrictModel, interval

#: The currency every price of the section is in.
CURRENCY = "USD"
#: Each tracker model of :data:`foldopt.names.TRACKERS` -> the field of :class:`Costs` that prices
#: its drive: one axis, or two (the equatorial mount turns a daily and a seasonal axis).
DRIVE_FIELD = {
    "single-axis": "drive_single_axis_usd",
    "dual-axis": "drive_dual_axis_usd",
    "dual-axis-steps": "drive_dual_axis_usd",
    "equatorial": "drive_dual_axis_usd",
}
#: The largest price a field takes [USD, or USD per unit].
MAX_PRICE = 1e9


def _price(unit: str):
    return interval(0, MAX_PRICE, unit=f" {CURRENCY}{unit}")


class Costs(StrictModel):
    """What a device's parts cost [USD]: the least-cost search's prices
    (:mod:`foldopt.studies.least_cost`); a design's cost is ``area_m2 x panel_usd_per_m2 +
    capacity_wh x buffer_usd_per_wh`` plus its kind's hinge or drive and ``fixed_usd``.

    Parameters
    ----------
    panel_usd_per_m2 : float
        The panel [USD/m^2] in [0, 1e9], per m^2 of its area (both halves of a twofold panel).
    buffer_usd_per_wh : float
        The buffer [USD/Wh] in [0, 1e9], per Wh of usable capacity (``storage.capacity_wh``).
    hinge_usd : float, default 0
        A twofold panel's fold hinge [USD] in [0, 1e9] (a flat panel has none).
    drive_single_axis_usd, drive_dual_axis_usd : float, optional
        A tracker's drive and mount [USD] in [0, 1e9], by the study's ``tracker.model``
        (:data:`DRIVE_FIELD`); a tracker whose drive has no price is left out of the search,
        and the answer says so.
    fixed_usd : float, default 0
        What every design costs besides [USD] in [0, 1e9] (the load, the controller, the pole):
        it moves every cost alike and no choice.
    """

    panel_usd_per_m2: _price("/m^2") = Field(description="the panel, per m^2 of its area")
    buffer_usd_per_wh: _price("/Wh") = Field(description="the buffer, per Wh of usable capacity")
    hinge_usd: _price("") = Field(0.0, description="a twofold panel's fold hinge")
    drive_single_axis_usd: _price("") | None = Field(
        None, description="a single-axis tracker's drive; default none: not searched"
    )
    drive_dual_axis_usd: _price("") | None = Field(
        None, description="a dual-axis tracker's drive; default none: not searched"
    )
    fixed_usd: _price("") = Field(0.0, description="every design's other parts")

    def drive_usd(self, tracker_model: str) -> float | None:
        """The drive's price [USD] of a tracker model of :data:`foldopt.names.TRACKERS`; None
        where the section gives none."""
        return getattr(self, DRIVE_FIELD[tracker_model])


def costs_problem(costs: Costs | None, storage, pv_model: str, iv_models) -> str | None:
    """Why a study's ``costs`` section cannot be searched, in one line; None where it can.

    The search scales each design's power with the panel's area, and sizes the buffer for
    ``storage.target``.

    Parameters
    ----------
    costs : Costs or None
    storage : foldopt.inputs.storage_section.Storage or None
    pv_model : str
        The study's.
    iv_models : tuple of str
        The PV models with an I-V curve (:data:`foldopt.names.IV_MODELS`).
    """
    if costs is None:
        return None
    if storage is None or storage.target is None:
        return (
            "costs: the least-cost search sizes the buffer for storage.target; give a storage "
            "section with a target (storage.target.powered_h, --target-h) or leave costs out"
        )
    if pv_model in iv_models:
        return (
            f"costs: the least-cost search scales the panel's power with its area, which holds "
            f"for pv_model ideal and pvwatts; pv_model {pv_model}'s I-V curve of a circuit of "
            "cells does not scale: use one of those or leave costs out"
        )
    return None
