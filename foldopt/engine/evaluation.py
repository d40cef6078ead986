"""The engine: daily metrics of many panel orientations over a :class:`foldopt.engine.sky.Sky`.

A *row* is one block of the sky (a day at a site) seen by one panel: the east and west sub-panel orientations
(a fold angle; both the same for the flat panel), the rows named by a :class:`PanelRows`. :func:`row_metrics`
gives, for every row, connection and load, ``t_solar``, optionally its longest contiguous interval, and the
energy and peak power of the electrical model of an :class:`foldopt.engine.options.ElectricalOptions`, in one
of two engines:

- ``numba``: :func:`foldopt.engine.kernel.fold_rows`, one compiled pass per row from the sun vector
  to the metrics, parallel over rows, without (rows x steps) arrays;
- ``numpy``: the reference, block by block: plane-of-array irradiance, the electrical model's powers and
  :mod:`foldopt.engine.metrics` on whole arrays. Tests hold the kernel to it (equal ``t_solar`` within 1 s a
  day and energy within 1e-9);
- ``auto`` (the default): the reference for small work, the kernel for more
  (:mod:`foldopt.engine.choice`).

Options that solve every step's I-V curves (``exact``) always take the reference path.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from foldopt.physics.connections import CONNECTIONS, connection_powers
from foldopt.physics.geometry import normal_vector, subpanel_orientation
from foldopt.physics.irradiance import beam_incidence_factor, plane_of_array
from foldopt.engine.metrics import energy, per_load, t_solar, t_solar_contiguous
from foldopt.names import DEFAULT_ENGINE
from foldopt.engine.choice import engine_for
from foldopt.engine.as_built import PARTS, assemble
from foldopt.engine.options import ElectricalOptions
from foldopt.engine.records import Loads, Rows, SkyArrays, Tables, allocate
from foldopt.engine.sky import Sky, step_span
from foldopt.engine.sky_view import row_views, surface_views

# The cells' electrical model is part of the engine's API (engines.electrical_for, panel_power...).
from foldopt.engine.cell_tables import (
    TEMPERATURE_NODE_STEP,  # noqa: F401
    electrical_for,
    node_weights,
    panel_power,  # noqa: F401
    temperature_nodes,
)

#: What :func:`row_metrics` can evaluate: the connections, and ``panel``, the whole panel as one.
OUTPUTS = CONNECTIONS + ("panel",)


@dataclass(frozen=True)
class RowMetrics:
    """Daily metrics per row, output (connection or ``panel``) and load.

    Attributes
    ----------
    t_solar : numpy.ndarray
        (n_rows, n_outputs, n_loads) [h].
    t_solar_contiguous : numpy.ndarray or None
        Longest contiguous interval [h], same shape, where asked for.
    energy : numpy.ndarray
        (n_rows, n_outputs) harvested energy [Wh].
    peak : numpy.ndarray
        (n_rows, n_outputs) peak power [W].
    irradiation : numpy.ndarray or None
        (n_rows,) plane-of-array irradiation [Wh/m^2], the mean of the two sub-panels (rows of orientations;
        None for given power curves).
    power : numpy.ndarray or None
        (n_curves, n_outputs, n_steps) [W]: the power curves the metrics of the rows asked for
        (:func:`row_metrics`' ``curves``) were reduced from; None where none were.
    """

    t_solar: np.ndarray
    t_solar_contiguous: np.ndarray | None
    energy: np.ndarray
    peak: np.ndarray
    irradiation: np.ndarray | None = None
    power: np.ndarray | None = None


class PanelRows(NamedTuple):
    """The rows :func:`row_metrics` evaluates: each a block of the sky seen by one panel's two
    sub-panels, against one set of loads.

    Attributes
    ----------
    block : array_like of int
        (n_rows,) each row's block.
    orientation : array_like
        (k, 4) the orientations the rows take: east tilt, east azimuth, west tilt, west azimuth
        [deg] (:func:`fold_orientations`, :func:`flat_orientation`).
    orientation_of : array_like of int, optional
        (n_rows,) each row's orientation in ``orientation``; default the row's own (row ``i``
        takes the ``i``-th, k = n_rows). A few orientations over many blocks (the angles of a
        search over a year's days) are so worked out once each.
    loadset : array_like of int, optional
        (n_rows,) each row's set of loads; default the first.
    """

    block: np.ndarray
    orientation: np.ndarray
    orientation_of: np.ndarray | None = None
    loadset: np.ndarray | None = None


def fold_orientations(geometry: str, surface_tilt, surface_azimuth, fold_angles) -> np.ndarray:
    """Sub-panel orientations of every block's panel at every fold angle.

    Parameters
    ----------
    geometry : str
        How the panel folds, one of :data:`foldopt.names.GEOMETRIES`.
    surface_tilt, surface_azimuth : array_like
        The flat panel of each block [deg], (n_blocks,).
    fold_angles : array_like
        [deg], (n_angles,).

    Returns
    -------
    numpy.ndarray
        (n_blocks, n_angles, 4): tilt and azimuth of the east, then of the west sub-panel [deg].
    """
    fold_angles = np.asarray(fold_angles, dtype=float)
    panels = np.stack(
        [np.asarray(surface_tilt, dtype=float), np.asarray(surface_azimuth, dtype=float)], axis=-1
    )
    unique, inverse = np.unique(panels, axis=0, return_inverse=True)
    per_panel = [
        design_orientations(geometry, fold_angles, tilt, azimuth) for tilt, azimuth in unique
    ]
    return np.stack(per_panel)[np.ravel(inverse)]


def design_orientations(geometry: str, fold_angle, surface_tilt, surface_azimuth) -> np.ndarray:
    """Sub-panel orientations of designs, each its own fold angle and flat panel.

    Parameters
    ----------
    geometry : str
        How the panel folds, one of :data:`foldopt.names.GEOMETRIES`.
    fold_angle, surface_tilt, surface_azimuth : array_like
        [deg], broadcast against each other.

    Returns
    -------
    numpy.ndarray
        (..., 4), the broadcast shape: tilt and azimuth of the east, then of the west sub-panel
        [deg], as :func:`fold_orientations` gives them.
    """
    sides = subpanel_orientation(fold_angle, surface_tilt, surface_azimuth, geometry)
    parts = ("tilt_east", "azimuth_east", "tilt_west", "azimuth_west")
    return np.stack([sides[f"surface_{part}"] for part in parts], axis=-1)


def flat_orientation(surface_tilt, surface_azimuth) -> np.ndarray:
    """The flat panel as (n_blocks, 4) row orientations, as :func:`fold_orientations`': both halves the panel.

    Parameters
    ----------
    surface_tilt, surface_azimuth : array_like
        The flat panel of each block [deg], (n_blocks,).
    """
    tilt, azimuth = np.asarray(surface_tilt, dtype=float), np.asarray(surface_azimuth, dtype=float)
    return np.stack([tilt, azimuth, tilt, azimuth], axis=-1)


def poa(
    sky: Sky,
    surface_tilt,
    surface_azimuth,
    blocks=slice(None),
    paper: bool = False,
    incident: bool = False,
    normal=None,
):
    """Plane-of-array irradiance [W/m^2] of surfaces over blocks of a sky (the reference path).

    Parameters
    ----------
    sky : Sky
    surface_tilt, surface_azimuth : array_like
        [deg], broadcast against the selected blocks' (n_blocks, n_steps): (n_blocks, 1) for one orientation
        per block, (n_blocks, n_steps) for a tracker, (k, 1) for k orientations over one selected block.
    blocks : slice or array_like, default all
        The blocks, as an index that keeps the block axis (a slice or a list).
    paper : bool
        The beam by Shin et al.'s Eq. 5 instead of the angle of incidence (fixed panels in paper mode; a
        tracker always takes the exact incidence).
    incident : bool
        The light incident on the surface, before the sky's incidence-angle modifier (the default is what
        reaches the cells).
    normal : array_like, optional
        The surfaces' unit normals (the broadcast shape and 3), where the caller has them (a tracker's):
        default worked out from the tilt and azimuth.

    Returns
    -------
    numpy.ndarray
        [W/m^2], the broadcast shape.
    """
    tilt, azimuth = np.asarray(surface_tilt, dtype=float), np.asarray(surface_azimuth, dtype=float)
    solar_zenith, solar_azimuth = sky.solar_zenith[blocks], sky.solar_azimuth[blocks]
    normal = normal_vector(tilt, azimuth) if normal is None else np.asarray(normal, dtype=float)
    sun = sky.sun_vector[blocks]
    # pvlib's aoi_projection (tested), without the (..., 3) temporary of a product.
    cos_aoi = (
        normal[..., 0] * sun[..., 0] + normal[..., 1] * sun[..., 1] + normal[..., 2] * sun[..., 2]
    )
    factor = (
        beam_incidence_factor(tilt, azimuth, solar_zenith, solar_azimuth, model="paper")
        if paper
        else None
    )
    terms = None if sky.terms is None else sky.terms[blocks]
    modifier = (
        1.0 if incident else iam_modifier(sky.iam, tilt, azimuth, solar_zenith, solar_azimuth)
    )
    views = None if terms is None else surface_views(sky, blocks, tilt, azimuth, normal[..., 2])
    return plane_of_array(cos_aoi, normal[..., 2], sky.dni[blocks], terms, factor, modifier, views)


def iam_modifier(model: str, surface_tilt, surface_azimuth, solar_zenith, solar_azimuth):
    """Incidence-angle modifier of the beam (pvlib ``iam.ashrae`` / ``iam.physical``), or 1.

    Parameters
    ----------
    model : {'none', 'ashrae', 'physical'}
    surface_tilt, surface_azimuth, solar_zenith, solar_azimuth : array_like
        [deg], broadcast.

    Returns
    -------
    numpy.ndarray or float
        Modifier [-], 0 for light from behind; 1.0 for ``none``.
    """
    if model == "none":
        return 1.0
    import pvlib

    aoi = pvlib.irradiance.aoi(surface_tilt, surface_azimuth, solar_zenith, solar_azimuth)
    modifier = pvlib.iam.ashrae(aoi) if model == "ashrae" else pvlib.iam.physical(aoi)
    return np.nan_to_num(np.asarray(modifier, dtype=float))


def _iam_code(model: str):
    """The kernel's incidence-angle modifier and its parameters: pvlib's defaults."""
    from foldopt.engine import incidence

    if model == "none":
        return incidence.IAM_NONE, np.zeros(3)
    import pvlib

    function = pvlib.iam.ashrae if model == "ashrae" else pvlib.iam.physical
    defaults = [
        p.default
        for p in inspect.signature(function).parameters.values()
        if p.default is not inspect.Parameter.empty and p.name != "n_ar"
    ]
    code = incidence.IAM_ASHRAE if model == "ashrae" else incidence.IAM_PHYSICAL
    return code, np.array(defaults + [0.0] * (3 - len(defaults)), dtype=float)


def _sorted_loads(loads):
    """Loads as (n_sets, n_loads), each set ascending, and the order that restores the caller's."""
    loads = np.atleast_2d(np.asarray(loads, dtype=float))
    order = np.argsort(loads, axis=1, kind="stable")
    return np.take_along_axis(loads, order, axis=1), order


def _unsort(values, order, row_loadset):
    """Put the last axis of per-row values back into each row's load order."""
    if (order == np.arange(order.shape[1])).all():
        return values  # the caller's loads were in order
    if order.shape[0] == 1:
        # one set of loads: one permutation for every row
        return np.take(values, np.argsort(order[0]), axis=-1)
    out = np.empty_like(values)
    np.put_along_axis(
        out, np.broadcast_to(order[row_loadset][:, None, :], values.shape), values, axis=-1
    )
    return out


def row_metrics(
    sky: Sky,
    *,
    rows: PanelRows,
    loads,
    electrical: ElectricalOptions,
    outputs=("switching",),
    contiguous: bool = False,
    engine: str = DEFAULT_ENGINE,
    curves=None,
) -> RowMetrics:
    """Daily metrics of rows of panel orientations over a sky.

    Parameters
    ----------
    sky : Sky
        The light, and how the beam is taken (paper mode: Eq. 5).
    rows : PanelRows
        Each row's block, orientation and set of loads.
    loads : array_like
        (n_loads,) loads [W] shared by every row, or (n_sets, n_loads) sets chosen by
        ``rows.loadset``.
    electrical : ElectricalOptions
        The electrical model and the connections' options.
    outputs : sequence of str
        Names of :data:`OUTPUTS` to evaluate.
    contiguous : bool
        Also the longest contiguous interval (costs O(n_loads) a step: for few loads).
    engine : {'auto', 'numba', 'numpy'}
    curves : array_like of int, optional
        Rows whose power curves to keep (``RowMetrics.power``, in this order): the curves their
        metrics were reduced from, for a report to draw.

    Returns
    -------
    RowMetrics
        An unknown ``engine`` or output raises ValueError.
    """
    engine = engine_for(engine, np.size(rows.block) * sky.n_steps)
    unknown = [name for name in outputs if name not in OUTPUTS]
    if unknown:
        raise ValueError(f"outputs must be among {', '.join(OUTPUTS)}; got {unknown}")
    block = np.asarray(rows.block, dtype=np.int64)
    orientation_of = (
        np.arange(block.size)
        if rows.orientation_of is None
        else np.asarray(rows.orientation_of, dtype=np.int64)
    )
    if orientation_of.size != block.size:
        raise ValueError(f"{orientation_of.size} orientations for {block.size} rows")
    rows = PanelRows(
        block,
        np.asarray(rows.orientation, dtype=float).reshape(-1, 4),
        orientation_of,
        np.zeros(block.size, dtype=np.int64)
        if rows.loadset is None
        else np.asarray(rows.loadset, dtype=np.int64),
    )
    sorted_loads, order = _sorted_loads(loads)
    held = _loads(sorted_loads, sky.load_shape, contiguous, sky.step_hours)
    curve = np.full(block.size, -1, dtype=np.int64)
    if curves is not None:
        curve[np.asarray(curves, dtype=np.int64)] = np.arange(np.size(curves))
    run = _reference if engine == "numpy" or electrical.exact else _compiled
    result = run(sky, rows, held, outputs, curve, electrical)
    return _in_caller_order(result, order, rows.loadset)


def _in_caller_order(result: RowMetrics, order, row_loadset) -> RowMetrics:
    contiguous = result.t_solar_contiguous
    return RowMetrics(
        _unsort(result.t_solar, order, row_loadset),
        None if contiguous is None else _unsort(contiguous, order, row_loadset),
        result.energy,
        result.peak,
        result.irradiation,
        result.power,
    )


def _curve_reference(power, row_loads, profile, loads: Loads):
    """t_solar, its longest run (or None), energy and peak of curves (m, n_steps) with loads (m, L)
    (scales of ``profile`` where ``loads.use_profile``) by :mod:`foldopt.engine.metrics`."""
    step_hours = loads.step_hours
    compared = per_load(power, profile if loads.use_profile else None)
    runs = (
        t_solar_contiguous(compared[:, None, :], row_loads, step_hours)
        if loads.contiguous
        else None
    )
    return (
        t_solar(compared[:, None, :], row_loads, step_hours),
        runs,
        energy(power, step_hours),
        power.max(axis=-1),
    )


def powers(
    sky: Sky,
    *,
    orientation,
    electrical: ElectricalOptions,
    blocks=slice(None),
    series: bool = True,
    with_state: bool = False,
):
    """Every connection's power [W] and the whole panel's (``panel``), and the switch state, from whole
    arrays: the reference path, and the source of time series for reports.

    Parameters
    ----------
    sky : Sky
        The light, and how the beam is taken (paper mode: Eq. 5).
    orientation : array_like
        (k, 4) sub-panel orientations over one selected block, or (n_blocks, 4), one per selected block.
    electrical : ElectricalOptions
        The electrical model and the connections' options.
    blocks : slice or list of int, default all
        The selected blocks (an index that keeps the block axis).
    series : bool, default True
        Whether to work out the series power (NaN otherwise).
    with_state : bool, default False
        Whether to return the switch state.

    Returns
    -------
    powers : dict of numpy.ndarray
        (k or n_blocks, n_steps) per name of :data:`OUTPUTS`, and ``poa``, the two sub-panels' mean incident
        plane-of-array irradiance [W/m^2] (before the incidence-angle modifier).
    state : numpy.ndarray or None
        The state switching chose (``with_state``).
    """
    orientation = np.asarray(orientation, dtype=float)
    paper = sky.mode == "paper"
    poa_east = poa(sky, orientation[:, 0, None], orientation[:, 1, None], blocks, paper)
    poa_west = poa(sky, orientation[:, 2, None], orientation[:, 3, None], blocks, paper)
    out = {}
    out["poa"] = (
        0.5 * (poa_east + poa_west)
        if sky.iam == "none"
        else 0.5
        * sum(
            poa(
                sky,
                orientation[:, 2 * side, None],
                orientation[:, 2 * side + 1, None],
                blocks,
                paper,
                incident=True,
            )
            for side in (0, 1)
        )
    )
    weights = node_weights(sky, blocks, poa_east.shape)
    circuit = electrical_for(electrical, weights[0][0], sky.wind_ref).circuit
    if circuit is not None:
        # As built, the panel side is taken linearly between tables and the converter acts on that.
        side = {name: np.zeros(poa_east.shape) for name in PARTS}
        for temp, weight in weights:
            take = weight > 0
            part = electrical_for(electrical, temp, sky.wind_ref).parts(
                poa_east[take], poa_west[take], series
            )
            for name, values in side.items():
                values[take] += weight[take] * part[name]
        connected, state = assemble(
            circuit,
            side,
            switch_series=electrical.switch_series,
            converter_efficiency=electrical.converter_efficiency,
            with_state=with_state,
        )
        return {**out, **connected}, state
    if len(weights) == 1:
        cells = electrical_for(electrical, weights[0][0], sky.wind_ref)
        part, state = cells.connections(poa_east, poa_west, series, with_state)
        part["panel"] = cells.panel_power(poa_east, electrical.area)
        return {**out, **part}, state
    # Steps between two tables' air temperatures take each sub-panel's and each pair's power
    # linearly between them, and the connections from those, as the kernel does.
    parts = {
        name: np.zeros(poa_east.shape) for name in ("east", "west", "parallel", "series", "panel")
    }
    for temp, weight in weights:
        take = weight > 0
        cells = electrical_for(electrical, temp, sky.wind_ref)
        part, _ = cells.connections(poa_east[take], poa_west[take], series, with_state=False)
        part["panel"] = cells.panel_power(poa_east[take], electrical.area)
        for name, values in parts.items():
            values[take] += weight[take] * part[name]
    connected, state = connection_powers(
        parts["east"],
        parts["west"],
        parts["parallel"],
        parts["series"],
        switch_series=electrical.switch_series,
        converter_efficiency=electrical.converter_efficiency,
        with_state=with_state,
    )
    return {**out, **connected, "panel": parts["panel"]}, state


def _reference(sky, rows: PanelRows, loads: Loads, outputs, curve, electrical) -> RowMetrics:
    """:func:`row_metrics` by the NumPy reference path, block by block (``rows`` complete)."""
    n_rows, n_loads, contiguous = rows.block.size, loads.p_load.shape[1], loads.contiguous
    orientation = rows.orientation[rows.orientation_of]
    shape = (n_rows, len(outputs))
    kept = int((curve >= 0).sum())
    out = RowMetrics(
        np.zeros(shape + (n_loads,)),
        np.zeros(shape + (n_loads,)) if contiguous else None,
        np.zeros(shape),
        np.zeros(shape),
        np.zeros(n_rows),
        np.zeros((kept, len(outputs), sky.dni.shape[1])) if kept else None,
    )
    series = "series" in outputs or electrical.switch_series
    step = sky.step_hours
    # The blocks in order; not np.unique, which imports numpy.ma (some 0.02 s) on its first call.
    for block in sorted(set(rows.block.tolist())):
        take = np.flatnonzero(rows.block == block)
        curves, _ = powers(
            sky, orientation=orientation[take], electrical=electrical, blocks=[block], series=series
        )
        out.irradiation[take] = energy(curves["poa"], step)
        profile = loads.profile[block] if loads.use_profile else None
        for index, name in enumerate(outputs):
            hours, runs, harvested, peak = _curve_reference(
                curves[name], loads.p_load[rows.loadset[take]], profile, loads
            )
            out.t_solar[take, index], out.energy[take, index], out.peak[take, index] = (
                hours,
                harvested,
                peak,
            )
            if contiguous:
                out.t_solar_contiguous[take, index] = runs
            keep = curve[take] >= 0
            if keep.any():
                out.power[curve[take][keep], index] = curves[name][keep]
    return out


def _tables(electricals, outputs, area: float) -> Tables:
    """The kernel's electrical side: the stacked tables (one per cell temperature), the power
    terms of a model without I-V curve, the circuit as built (its flags, tables and converter)
    and the codes of the ``outputs``; ``area`` the panel's [m^2]."""
    first, count = electricals[0], len(electricals)
    parts = first.circuit
    # Tables the options do not use are placeholders, one per cell temperature all the same.
    placeholder_1d, placeholder = np.zeros((count, 2)), np.zeros((count, 2, 2))
    subpanel, parallel, series, power_terms = placeholder_1d, placeholder, placeholder, None
    alone, panel, switching = placeholder_1d, placeholder_1d, placeholder
    if not first.pv.has_iv:
        power_terms = np.array(
            [
                e.pv.power_terms(e.temp_air, e.wind_speed, e.temperature_model, e.subpanel_area)
                for e in electricals
            ],
            dtype=float,
        )
    else:
        subpanel = np.stack([e._table("subpanel")[1] for e in electricals])
        parallel = np.stack([e._table("parallel") for e in electricals])
        if "series" in outputs or first.switch_series:
            series = np.stack([e._table("series") for e in electricals])
        if parts is not None and parts.direct:
            alone = np.stack([e._table("alone")[1] for e in electricals])
            panel = np.stack([e._table("panel")[1] for e in electricals])
        if parts is not None and parts.switch_table:
            switching = np.stack([e._table("switching") for e in electricals])
    return Tables(
        subpanel=subpanel,
        parallel=parallel,
        series=series,
        power_terms=np.zeros((0, 2)) if power_terms is None else power_terms,
        panel_scale=float(area / first.subpanel_area),
        bypass=bool(first.bypass),
        switch_series=bool(first.switch_series),
        converter_efficiency=float(first.converter_efficiency),
        connections=np.array([OUTPUTS.index(name) for name in outputs], dtype=np.int64),
        as_built=parts is not None,
        direct=parts is not None and bool(parts.direct),
        switch_table=parts is not None and bool(parts.switch_table),
        alone=alone,
        panel=panel,
        switching=switching,
        converter=np.zeros(1)
        if parts is None
        else np.ascontiguousarray(parts.conv_table, dtype=float),
        converter_rating=0.0 if parts is None else float(parts.conv_rated),
    )


def _sky_arrays(sky: Sky, paper: bool, table, weight) -> SkyArrays:
    """The kernel's light: the sky along its steps, each step's (or block's) table set and weight
    (:func:`temperature_nodes`), and how the beam is taken."""
    iam_model, iam_params = _iam_code(sky.iam)
    sun, paper_sun, beam, terms, span = (np.ascontiguousarray(a) for a in sky.kernel_layout(paper))
    # One layout for every call, so that one compiled specialisation (cached on disk) serves all.
    return SkyArrays(
        sun=sun,
        paper_sun=paper_sun,
        beam=beam,
        terms=terms,
        span=span,
        step_table=np.ascontiguousarray(table, dtype=np.int64),
        step_weight=np.ascontiguousarray(weight, dtype=float),
        paper=paper,
        iam_model=int(iam_model),
        iam_params=iam_params,
    )


def _kernel_rows(sky: Sky, rows: PanelRows, curve, paper: bool) -> Rows:
    """The kernel's rows: each orientation's normals (and Eq. 5 factors) worked out once, then
    taken per row; the exact incidence reads no Eq. 5 factors (zeros stand in)."""
    orientation, orientation_of = rows.orientation, rows.orientation_of
    # (n_orientations, 2, 3): both sides in one call, east's tilt and azimuth then west's
    normals = normal_vector(orientation[:, 0::2], orientation[:, 1::2])
    row_paper = np.zeros((rows.block.size, 2, 4))
    if paper:
        tilt, azimuth = np.radians(orientation[:, 0::2]), np.radians(orientation[:, 1::2])
        row_paper = np.stack(
            [np.cos(tilt), np.sin(tilt), np.cos(azimuth), np.sin(azimuth)], axis=-1
        )[orientation_of]
    return Rows(
        block=np.ascontiguousarray(rows.block),
        # take: a fifth of fancy indexing's cost over a search's tens of thousands of rows
        normal=np.take(normals, orientation_of, axis=0),
        paper=np.ascontiguousarray(row_paper),
        sky_view=np.ascontiguousarray(
            row_views(sky, rows.block, normals, orientation, orientation_of)
        ),
        loadset=np.ascontiguousarray(rows.loadset),
        curve=curve,
    )


def _compiled(sky, rows: PanelRows, loads: Loads, outputs, curve, electrical) -> RowMetrics:
    """:func:`row_metrics` by the compiled kernel (``rows`` complete): the records of
    :mod:`foldopt.engine.records` filled, then one pass of :func:`foldopt.engine.kernel.fold_rows`."""
    from foldopt.engine import kernel

    nodes, table, weight = temperature_nodes(sky)
    electricals = [electrical_for(electrical, temp, sky.wind_ref) for temp in nodes]
    paper = sky.mode == "paper"
    kept = int((curve >= 0).sum())
    out, scratch = allocate(
        rows.block.size,
        len(outputs),
        loads.p_load.shape[1],
        sky.dni.shape[1],
        loads.contiguous,
        kept,
    )
    kernel.fold_rows(
        _sky_arrays(sky, paper, table, weight),
        _kernel_rows(sky, rows, curve, paper),
        _tables(electricals, outputs, electrical.area),
        loads,
        out,
        scratch,
    )
    return RowMetrics(
        out.t_solar,
        out.t_solar_contiguous if loads.contiguous else None,
        out.energy,
        out.peak,
        out.irradiation,
        out.power if kept else None,
    )


def power_span(power) -> np.ndarray:
    """(n_rows, 2) each curve's first and last step with power, and one step without either side
    ((0, 0) for a curve without any): what :func:`foldopt.engine.curve_reduction.curve_rows` walks.

    Parameters
    ----------
    power : numpy.ndarray
        (n_rows, n_steps) [W].
    """
    return step_span(power != 0.0)


def _loads(sorted_loads, load_shape, contiguous: bool, step_hours: float) -> Loads:
    """The engine's :class:`Loads`: one placeholder row (1, 1) of profile for constant loads.

    The profile is always read-only (a broadcast load shape is, a copied one or the placeholder
    would not be): numba compiles a loop again for each array type it is called with, read-only
    or not, and the compiled loops only read it."""
    profile = (
        np.zeros((1, 1)) if load_shape is None else np.ascontiguousarray(load_shape, dtype=float)
    ).view()
    profile.flags.writeable = False
    return Loads(
        p_load=np.ascontiguousarray(sorted_loads, dtype=float),
        profile=profile,
        use_profile=load_shape is not None,
        contiguous=bool(contiguous),
        step_hours=float(step_hours),
    )


def curve_metrics(
    power,
    loads,
    step_hours: float,
    row_loadset=None,
    contiguous: bool = False,
    engine: str = DEFAULT_ENGINE,
    load_shape=None,
    span=None,
) -> RowMetrics:
    """Daily metrics of given power curves (a tracker's, a design's).

    Parameters
    ----------
    power : array_like
        (n_rows, n_steps) power at step centres [W].
    loads : array_like
        (n_loads,) loads [W], or (n_sets, n_loads) sets chosen by ``row_loadset``.
    step_hours : float
        Step length [h].
    row_loadset : array_like of int, optional
        (n_rows,) set of loads of each row; default the first.
    contiguous : bool, default False
        Also the longest contiguous interval.
    engine : {'auto', 'numba', 'numpy'}
    load_shape : array_like, optional
        (n_rows, n_steps) load profile [W]; the loads are then its scales (:func:`per_load`).
    span : array_like of int, optional
        (n_rows, 2) the first and last step of each curve with power and one without either side
        (:func:`power_span`, its default): what the compiled engine walks; a row given (0, 0) is
        not walked (its metrics are then those of no power).

    Returns
    -------
    RowMetrics
        With one output: ``t_solar`` (n_rows, 1, n_loads) and so on; no irradiation. An unknown ``engine``
        raises ValueError.
    """
    power = np.ascontiguousarray(power, dtype=float)
    sorted_loads, order = _sorted_loads(loads)
    # The reference path walks every step once a load; the kernel walks the loads along the curve.
    engine = engine_for(engine, power.size * sorted_loads.shape[1])
    row_loadset = (
        np.zeros(power.shape[0], dtype=np.int64)
        if row_loadset is None
        else np.asarray(row_loadset, dtype=np.int64)
    )
    if load_shape is not None:
        load_shape = np.broadcast_to(np.asarray(load_shape, dtype=float), power.shape)
    held = _loads(sorted_loads, load_shape, contiguous, step_hours)
    if engine == "numpy":
        hours, runs, harvested, peak = _curve_reference(
            power, sorted_loads[row_loadset], held.profile, held
        )
        result = RowMetrics(
            hours[:, None],
            None if runs is None else runs[:, None],
            harvested[:, None],
            peak[:, None],
        )
    else:
        from foldopt.engine import curve_reduction

        out, scratch = allocate(power.shape[0], 1, sorted_loads.shape[1], 0, contiguous)
        span = power_span(power) if span is None else np.ascontiguousarray(span, dtype=np.int64)
        curve_reduction.curve_rows(power, span, row_loadset, held, out, scratch)
        result = RowMetrics(
            out.t_solar, out.t_solar_contiguous if contiguous else None, out.energy, out.peak
        )
    return _in_caller_order(result, order, row_loadset)
