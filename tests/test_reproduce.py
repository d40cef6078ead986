"""Reproduction of Shin et al.: the paper-mode column against the published numbers."""

import numpy as np
import pytest

from foldopt.studies.reproduce import PAPER_VALUES, infer_p_load, reproduce

# The acceptance bands around Shin et al. Sec. VII / Fig. 12 values.
TOLERANCE = {
    "t_solar_flat_h": 0.2,
    "t_solar_tracker_h": 0.2,
    "t_solar_twofold_h": 0.2,
    "fold_angle_twofold_deg": 2.5,
    "gain_vs_flat_twofold_pct": 2.5,
    "share_of_tracker_twofold_pct": 2.5,
    "gain_vs_flat_twofold90_pct": 2.5,
    "flat_area_twofold_ratio": 0.3,
}


@pytest.fixture(scope="session")
def table(shin_study):
    return reproduce(shin_study).set_index("quantity")


@pytest.fixture(scope="session")
def single_diode_table(shin_study):
    return reproduce(shin_study, pv_model="single-diode").set_index("quantity")


def test_table_has_the_agreed_shape(table):
    assert list(table.index) == list(PAPER_VALUES)
    assert list(table.columns) == ["unit", "paper", "paper_mode", "exact_mode"]
    assert table[["paper_mode", "exact_mode"]].notna().all().all()


@pytest.mark.parametrize("quantity", list(TOLERANCE))
def test_paper_mode_lands_near_the_paper(table, quantity):
    row = table.loc[quantity]
    assert row["paper_mode"] == pytest.approx(row["paper"], abs=TOLERANCE[quantity])


def test_inferred_load_is_the_one_in_the_config(shin_study, table):
    # configs/shin2015.yaml documents the inferred load rounded to 1 mW.
    assert table.loc["p_load_w", "paper_mode"] == pytest.approx(shin_study.p_load, abs=1e-3)
    assert table.loc["p_load_w", "exact_mode"] == table.loc["p_load_w", "paper_mode"]
    assert np.isnan(table.loc["p_load_w", "paper"])


def test_flat_t_solar_is_pinned_by_the_inference(shin_study, table):
    assert table.loc["t_solar_flat_h", "paper_mode"] == pytest.approx(7.73, abs=1e-6)
    assert infer_p_load(shin_study, 9.0) < infer_p_load(shin_study, 7.73)


@pytest.mark.parametrize("quantity", list(TOLERANCE))
def test_single_diode_paper_mode_lands_near_the_paper(single_diode_table, quantity):
    # The paper's own model: A-300 single-diode sub-panels with switching.
    row = single_diode_table.loc[quantity]
    assert row["paper_mode"] == pytest.approx(row["paper"], abs=TOLERANCE[quantity])


def test_single_diode_reproduces_the_papers_twofold_numbers_closely(single_diode_table, table):
    # With the cell model the paper used, the twofold time, the gain and the area multiple come
    # closer to the paper than with the ideal model (measured: 9.49 h, +22.8 %, 2.61).
    for quantity in ("t_solar_twofold_h", "gain_vs_flat_twofold_pct", "flat_area_twofold_ratio"):
        paper = table.loc[quantity, "paper"]
        assert (abs(single_diode_table.loc[quantity, "paper_mode"] - paper)
                < abs(table.loc[quantity, "paper_mode"] - paper))
