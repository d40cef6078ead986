"""Reproduction of Shin et al.'s twofold study, in paper and exact modes side by side.

The load is not printed in the paper; it is inferred in paper mode as the load at which the flat
panel's ``t_solar`` equals the paper's 7.73 h, and the same load is then used in both modes (it is
a property of the device, not of the physics). Each PV model gets its own inference, since the
paper's 7.73 h is what its own model gave.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pandas as pd

from foldopt.inputs.study import Study
from foldopt.engine.metrics import load_for_t_solar
from foldopt.studies.day import Day, run_study, twofold_t_solar
from foldopt.names import DEFAULT_ENGINE

#: Shin et al. Sec. VI-VII and Fig. 12: (unit, published value); NaN where the paper is silent.
PAPER_VALUES = {
    "p_load_w": ("W", np.nan),
    "t_solar_flat_h": ("h", 7.73),
    "t_solar_tracker_h": ("h", 11.11),
    "fold_angle_twofold_deg": ("deg", 29.8),
    "t_solar_twofold_h": ("h", 9.49),
    "gain_vs_flat_twofold_pct": ("%", 23.0),
    "share_of_tracker_twofold_pct": ("%", 85.4),
    "gain_vs_flat_twofold90_pct": ("%", 15.5),
    "flat_area_twofold_ratio": ("-", 2.61),
}
GEOMETRY_OF_MODE = {"paper": "azimuth-split", "exact": "hinge"}
#: The reproduction tables `foldopt reproduce` writes: file stem -> changes to the paper study.
REPRODUCTIONS = {
    "reproduction": {},
    "reproduction_single_diode": {"pv_model": "single-diode", "connection": "switching"},
}


@dataclass(frozen=True)
class Reproduction:
    """The reproduction tables (:func:`foldopt.studies.reproduce`), the paper's study and the engine."""

    tables: dict
    study: Study
    engine: str = DEFAULT_ENGINE

    @functools.cached_property
    def answer(self):
        """The :class:`foldopt.studies.answer.Answer` every view renders."""
        from foldopt.studies.result_answers import of_reproduction

        return of_reproduction(self.tables, self.study)


def infer_p_load(study: Study, t_solar_flat_h: float = PAPER_VALUES["t_solar_flat_h"][1]) -> float:
    """Load at which the study's flat panel, in paper mode, runs ``t_solar_flat_h`` hours.

    The paper does not state its load; on the paper's study this gives 4.398 W.

    Parameters
    ----------
    study : Study
        The paper's study (``configs/shin2015.yaml``) or a variant.
    t_solar_flat_h : float, default 7.73
        The flat panel's ``t_solar`` [h] (Shin et al. Sec. IV-A).

    Returns
    -------
    float
        Load [W] (:func:`foldopt.engine.metrics.load_for_t_solar`).
    """
    day = Day(study.variant(mode="paper"))
    return load_for_t_solar(day.flat_power(), t_solar_flat_h, day.step_hours)


def reproduction_values(study: Study, engine: str = DEFAULT_ENGINE) -> dict[str, float]:
    """The reproduced quantities of :data:`PAPER_VALUES` for one resolved study.

    Parameters
    ----------
    study : Study
        Mode, geometry and load already set (:func:`reproduce`).
    engine : {'auto', 'numba', 'numpy'}

    Returns
    -------
    dict of float
        One value per quantity of :data:`PAPER_VALUES`, in its unit.
    """
    result = run_study(study, engine)
    summary = result.summary.set_index("design")
    flat, twofold, tracker = (summary.loc[name] for name in ("flat", "twofold", "tracker"))
    t_solar_twofold90 = twofold_t_solar(result.day, 90.0)
    return {
        "p_load_w": study.p_load,
        "t_solar_flat_h": flat["t_solar_h"],
        "t_solar_tracker_h": tracker["t_solar_h"],
        "fold_angle_twofold_deg": twofold["fold_angle_deg"],
        "t_solar_twofold_h": twofold["t_solar_h"],
        "gain_vs_flat_twofold_pct": twofold["gain_vs_flat_pct"],
        "share_of_tracker_twofold_pct": twofold["share_of_tracker_pct"],
        "gain_vs_flat_twofold90_pct": (t_solar_twofold90 / flat["t_solar_h"] - 1.0) * 100.0,
        "flat_area_twofold_ratio": twofold["flat_area_ratio"],
    }


def reproduce(study: Study, engine: str = DEFAULT_ENGINE, **changes) -> pd.DataFrame:
    """Paper value, paper-mode value and exact-mode value of each reproduced quantity.

    Parameters
    ----------
    study : Study
        The paper's study (``configs/shin2015.yaml``); its mode, geometry and load are replaced:
        paper mode with the azimuth-split geometry, exact mode with the hinge, and the inferred load.
    engine : {'auto', 'numba', 'numpy'}
        :data:`foldopt.engine.evaluation.ENGINES`.
    **changes
        Other fields to replace first, e.g. ``pv_model="single-diode"``.

    Returns
    -------
    pandas.DataFrame
        Columns ``quantity, unit, paper, paper_mode, exact_mode``.
    """
    study = study.variant(**changes)
    p_load = infer_p_load(study)
    columns = {}
    for mode, geometry in GEOMETRY_OF_MODE.items():
        # Both modes with the study's PV model: the columns differ by the modes' physics alone.
        variant = study.variant(
            mode=mode, geometry=geometry, p_load=p_load, pv_model=study.pv_model
        )
        columns[f"{mode}_mode"] = reproduction_values(variant, engine)
    return pd.DataFrame(
        [
            {
                "quantity": quantity,
                "unit": unit,
                "paper": paper,
                "paper_mode": columns["paper_mode"][quantity],
                "exact_mode": columns["exact_mode"][quantity],
            }
            for quantity, (unit, paper) in PAPER_VALUES.items()
        ]
    )
