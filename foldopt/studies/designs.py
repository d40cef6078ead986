"""The designs, evaluated once: flat, twofold at every fold angle, trackers gross and net.

Every study that compares designs takes them from here: the flat, twofold, tracker and
tracker-net rows of a single day (:func:`foldopt.studies.day.run_study`, which adds the heuristic's
angle, the other connections and the other tracker models from their power curves), the cases and
annual groups of :func:`foldopt.studies.sweeps.run_plan` and the sites of
:func:`foldopt.studies.worldmap.evaluate_sites`; all over :class:`Blocks` of a sky (days at sites that
share one setup) and a set of loads:

- :func:`fold_hours`: t_solar of the twofold panel at every angle of the study's grid, for every
  load, in one engine pass; :mod:`foldopt.studies.objectives` chooses from it;
- :func:`design_metrics`: every daily metric of the four :data:`DESIGNS` at a chosen angle;
- :func:`daily_designs`: each day's t_solar and energy of every design at every angle, for
  statistics over many days (:func:`foldopt.studies.objectives.objective_value`);
- the trackers' orientation, power and own draw, worked out once a sky (:func:`tracker_curves`,
  which a day's figures draw and its table's rows are reduced from), and what a standby draw
  leaves (:func:`standby_available`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from foldopt.engine import evaluation as engines
from foldopt.engine.choice import engine_for
from foldopt.physics.connections import CONNECTIONS
from foldopt.inputs.study import Study
from foldopt.engine.metrics import design_condition, energy, energy_served, metric_columns
from foldopt.engine.sky import Sky
from foldopt.studies.engine_options import engine_options

# Blocks and their setup are part of the designs' API (the studies take them from here).
from foldopt.studies.blocks import CHUNK_ROW_LOADS, Blocks, setup_key  # noqa: F401
from foldopt.physics.trackers import TrackerDrive, TrackerOptions, tracker_draw, tracker_orientation
from foldopt.names import DEFAULT_ENGINE, FLAT_FOLD_ANGLE

DESIGNS = ("flat", "twofold", "tracker", "tracker-net")
#: The design of an existing array's planes as they stand (``panel.planes``), which a day's study
#: and an annual group evaluate beside :data:`DESIGNS`.
PLANES_DESIGN = "twofold-planes"


def sky_tracker_orientation(sky: Sky, study: Study, model: str | None = None):
    """Surface tilt and azimuth of a tracker [deg] over every block, (n_blocks, n_steps) each,
    and its unit normal, (n_blocks, n_steps, 3) (:func:`foldopt.physics.trackers.tracker_orientation`).

    Parameters
    ----------
    sky : Sky
    study : Study
        The tracker's settings.
    model : str, optional
        One of :data:`foldopt.names.TRACKERS`; default the study's.
    """
    tracker = study.tracker
    options = TrackerOptions(
        steps=tracker.steps,
        angular_field=tracker.angular_field,
        step_offsets_h=tuple(tracker.step_offsets_h or TrackerOptions().step_offsets_h),
        axis_tilt=tracker.axis_tilt,
        axis_azimuth=tracker.axis_azimuth,
        max_angle=tracker.max_angle,
        backtrack=tracker.backtrack,
        gcr=tracker.gcr,
    )
    return tracker_orientation(
        model or tracker.model,
        sky.solar_zenith,
        sky.solar_azimuth,
        sky.hour_angle,
        sky.declination,
        np.asarray(sky.latitude)[:, None],
        options,
        sky.sun_vector,
    )


def sky_tracker_power(sky: Sky, study: Study, orientation) -> np.ndarray:
    """Power [W] of the study's panel on a tracker of that ``orientation`` over every block.

    Trackers take the exact angle of incidence in both modes: Eq. 5 is the paper's formula for its
    fixed panels (it reads an azimuth even for a level panel, which a single-axis tracker is at
    noon), and for the paper's only tracker, the ideal one, both give 1.

    Parameters
    ----------
    sky : Sky
    study : Study
    orientation : tuple of numpy.ndarray
        The tracker's surface tilt and azimuth [deg] and normal (:func:`sky_tracker_orientation`).

    Returns
    -------
    numpy.ndarray
        (n_blocks, n_steps) [W].
    """
    return engines.panel_power(
        sky,
        poa_global=sky_tracker_poa(sky, orientation),
        electrical=engine_options(study).electrical,
    )


def sky_tracker_poa(sky: Sky, orientation, engine: str = "auto") -> np.ndarray:
    """Irradiance [W/m^2] reaching a tracker's cells (after the sky's incidence-angle modifier)
    over every block, (n_blocks, n_steps).

    Parameters
    ----------
    sky : Sky
    orientation : tuple of numpy.ndarray
        The tracker's surface tilt and azimuth [deg] and normal (:func:`sky_tracker_orientation`).
    engine : {'auto', 'numba', 'numpy'}
        ``auto`` decides by the sky's size; a request that has decided its engine (a map's
        worker, whose chunk's skies are each under ``auto``'s bound) passes it.
    """
    tilt, azimuth, normal = orientation
    small = engine_for(engine, sky.n_blocks * sky.n_steps) == "numpy"
    if sky.horizon_of is not None or sky.iam != "none" or small:
        return engines.poa(sky, tilt, azimuth, normal=normal)
    # An open plain without a modifier (every map's): the same sums compiled, over the lit spans
    # alone (the reference path's to the bit, tests/test_tracker.py), where they save more than
    # their compile costs.
    from foldopt.engine.incidence import turning_poa

    sun, _, beam, terms, span = sky.kernel_layout(False)
    poa = np.empty(beam.shape)
    # The normal's components each along the steps, as the sun's, C-contiguous whatever the
    # tracker and the number of blocks: one array type for the compiled pass (a view would be
    # typed F for one block and A for several, each compiled).
    along = np.ascontiguousarray(np.moveaxis(normal, -1, 1), dtype=float)
    turning_poa(along, sun, beam, terms, span, poa)
    return poa


def standby_available(gross, draw, lit, standby_w: float):
    """The tracker's power [W] left for the load and its standby: ``gross`` less ``draw`` but the
    standby (its moves only), where there is light (``lit``), 0 elsewhere. A standby draw ``s``
    (drawn wherever there is light) is then the load ``P_load + s`` on this curve, as there is no
    power where no standby is drawn.

    Parameters
    ----------
    gross, draw : array_like
        The tracker's power and its own draw (:func:`sky_tracker_draw`) per step [W].
    lit : array_like of bool
        Steps with light (:attr:`foldopt.engine.sky.Sky.lit`).
    standby_w : float
        The standby part of ``draw`` [W].
    """
    left = np.subtract(draw, standby_w)
    return np.where(lit, np.subtract(gross, left, out=left), 0.0)


def sky_tracker_draw(
    sky: Sky, study: Study, orientation, every: int = 1, engine: str = "auto"
) -> np.ndarray:
    """The tracker's own draw [W] per step over every block: standby while there is light (the sun up,
    clouds or not), plus its moves.

    Parameters
    ----------
    sky : Sky
    study : Study
        The tracker's drive and standby settings.
    orientation : tuple of numpy.ndarray
        The tracker's surface tilt and azimuth [deg] and normal (:func:`sky_tracker_orientation`).
    every : int, default 1
        Work out every ``every``-th block's draw and give it to the next ``every``: a cloud
        ensemble's members share their day's sun, so the tracker moves alike, and some light
        reaches every member while the sun is up.
    engine : {'auto', 'numba', 'numpy'}
        The moves' passes (:func:`foldopt.physics.trackers.tracker_draw`), the same bits either
        way; ``auto`` decides by the sky's size, a request that has decided its engine passes it.
    """
    tracker = study.tracker
    drive = TrackerDrive(
        standby_w=tracker.standby_w, drive=tracker.drive, wh_per_degree=tracker.wh_per_degree
    )
    shared = slice(None, None, every)
    engine = engine_for(engine, sky.n_blocks * sky.n_steps)
    draw = tracker_draw(orientation[2][shared], sky.lit[shared], sky.step_hours, drive, engine)
    return np.repeat(draw, every, axis=0) if every > 1 else draw


@dataclass(frozen=True)
class TrackerCurves:
    """A tracker over every block of a sky, worked out once: what the metrics of its rows are
    reduced from and what a day's figures draw.

    Attributes
    ----------
    orientation : tuple of numpy.ndarray
        Surface tilt and azimuth [deg], (n_blocks, n_steps) each, and unit normal,
        (n_blocks, n_steps, 3) (:func:`sky_tracker_orientation`).
    power : numpy.ndarray
        Gross power [W], (n_blocks, n_steps) (:func:`sky_tracker_power`).
    draw : numpy.ndarray
        Its own draw [W], (n_blocks, n_steps) (:func:`sky_tracker_draw`).
    incident : numpy.ndarray or None
        The plane-of-array irradiance incident on it [W/m^2], (n_blocks, n_steps), where it is
        what the power came from (a sky without an incidence-angle modifier); None otherwise.
    """

    orientation: tuple
    power: np.ndarray
    draw: np.ndarray
    incident: np.ndarray | None = None

    @property
    def net(self) -> np.ndarray:
        """What is left for the load after the tracker's own draw [W], (n_blocks, n_steps)."""
        return np.subtract(self.power, self.draw)

    def gross_and_net(self) -> np.ndarray:
        """:attr:`power` above :attr:`net`, (2 n_blocks, n_steps) [W], for one engine call over
        both: the net written into its place, not made and copied."""
        n_blocks = self.power.shape[0]
        both = np.empty((2 * n_blocks, self.power.shape[1]))
        both[:n_blocks] = self.power
        np.subtract(self.power, self.draw, out=both[n_blocks:])
        return both


def tracker_curves(
    sky: Sky, study: Study, model: str | None = None, every: int = 1, engine: str = "auto"
) -> TrackerCurves:
    """A tracker's orientation, power and own draw over every block of a sky.

    Parameters
    ----------
    sky : Sky
    study : Study
        The panel and the tracker's settings.
    model : str, optional
        One of :data:`foldopt.names.TRACKERS`; default the study's.
    every : int, default 1
        As :func:`sky_tracker_draw`'s (a cloud ensemble's members share their day's draw).
    engine : {'auto', 'numba', 'numpy'}
        As :func:`sky_tracker_poa`'s and :func:`sky_tracker_draw`'s.
    """
    orientation = sky_tracker_orientation(sky, study, model)
    poa = sky_tracker_poa(sky, orientation, engine)
    draw = sky_tracker_draw(sky, study, orientation, every, engine)
    power = engines.panel_power(sky, poa_global=poa, electrical=engine_options(study).electrical)
    return TrackerCurves(orientation, power, draw, poa if sky.iam == "none" else None)


def fold_hours(sky: Sky, blocks: Blocks, loads, engine: str = DEFAULT_ENGINE, fold_angles=None):
    """t_solar [h] of every block's twofold panel at every angle of the grid, for every load.

    Parameters
    ----------
    sky : Sky
        The blocks' sky.
    blocks : Blocks
    loads : array_like
        (n_loads,) [W].
    engine : {'auto', 'numba', 'numpy'}
    fold_angles : array_like, optional
        [deg]; default the study's grid.

    Returns
    -------
    fold_angles : numpy.ndarray
        The fold angles [deg], (n_angles,).
    hours : numpy.ndarray
        (n_blocks, n_angles, n_loads).
    energy : numpy.ndarray
        Harvested energy [Wh], (n_blocks, n_angles).
    """
    study = blocks.study
    grid = study.fold_angles.grid() if fold_angles is None else fold_angles
    fold_angles = np.asarray(grid, dtype=float)
    orientation = engines.fold_orientations(
        study.geometry, blocks.tilt, blocks.azimuth, fold_angles
    )
    metrics = engines.row_metrics(
        sky,
        rows=engines.PanelRows(
            np.repeat(np.arange(sky.n_blocks), fold_angles.size), orientation.reshape(-1, 4)
        ),
        loads=loads,
        electrical=blocks.options.electrical,
        outputs=(study.connection,),
        engine=engine,
    )
    return (
        fold_angles,
        metrics.t_solar.reshape(sky.n_blocks, fold_angles.size, -1),
        metrics.energy.reshape(sky.n_blocks, fold_angles.size),
    )


def design_metrics(
    sky: Sky,
    blocks: Blocks,
    loads,
    fold_angles,
    chosen,
    engine: str,
    tracker: TrackerCurves | None = None,
    *,
    curves: bool = False,
    curve_outputs: tuple = CONNECTIONS,
) -> dict:
    """Metrics of every design per block and load, each (n_blocks, n_loads, 4 designs): the twofold
    panel at grid index ``chosen`` (n_blocks, n_loads), the flat panel, the tracker gross and net.

    Parameters
    ----------
    sky : Sky
    blocks : Blocks
    loads : numpy.ndarray
        (n_loads,) [W].
    fold_angles : numpy.ndarray
        The fold-angle grid [deg].
    chosen : numpy.ndarray of int
        (n_blocks, n_loads) index into ``angles`` of the twofold panel's angle.
    engine : {'auto', 'numba', 'numpy'}
    tracker : TrackerCurves, optional
        The study's tracker over ``sky``, where the caller has it (a day's study draws it too);
        default worked out here (:func:`tracker_curves`).
    curves : bool, default False
        Also the power curves [W] the flat and twofold rows were reduced from, for a report to
        draw: the twofold panel's then of each of ``curve_outputs`` at its chosen angle.
    curve_outputs : tuple of str, default every connection
        With ``curves``, the connections whose curves to keep beside the study's own.

    Returns
    -------
    dict of numpy.ndarray
        ``fold_angle_deg``, the :func:`foldopt.engine.metrics.metric_columns`,
        ``poa_global_wh_m2`` (incident irradiation [Wh/m^2]) and ``condition``
        (:func:`foldopt.engine.metrics.design_condition`), each (n_blocks, n_loads, 4) in the
        order of :data:`DESIGNS`; with ``curves``, also ``curves``: a dict of ``flat``, (n_blocks,
        n_steps), and of the study's connection and each of ``curve_outputs``, (n_blocks,
        n_loads, n_steps).
    """
    study, blocks_of = blocks.study, blocks
    electrical = blocks.options.electrical
    n_blocks, n_loads = sky.n_blocks, loads.size
    tilt, azimuth = blocks.tilt, blocks.azimuth
    every = engines.fold_orientations(study.geometry, tilt, azimuth, fold_angles)
    blocks = np.repeat(np.arange(n_blocks), n_loads)
    shape = sky.load_shape
    # One row per block and load, at that load's angle, with the load alone; the curves kept where
    # asked for and where a load profile's served energy integrates over them. A sweep's chosen
    # angle was in fold_hours' pass too, but without the longest runs, which would cost that pass
    # 1.4x (one load) to 4.5x (50 loads), some 3 to 10 times this pass; its t_solar, of every load
    # at once, differs from this row's in the last bits (the loads' bins are summed in another order).
    outputs = (
        tuple(dict.fromkeys((study.connection, *curve_outputs))) if curves else (study.connection,)
    )
    own = outputs.index(study.connection)
    keep = curves or shape is not None
    twofold = engines.row_metrics(
        sky,
        rows=engines.PanelRows(
            blocks,
            every[blocks, chosen.ravel()],
            loadset=np.tile(np.arange(n_loads), n_blocks),
        ),
        loads=loads[:, None],
        electrical=electrical,
        outputs=outputs,
        contiguous=True,
        engine=engine,
        curves=np.arange(blocks.size) if keep else None,
    )
    flat = engines.row_metrics(
        sky,
        rows=engines.PanelRows(np.arange(n_blocks), engines.flat_orientation(tilt, azimuth)),
        loads=loads,
        electrical=electrical,
        outputs=("panel",),
        contiguous=True,
        engine=engine,
        curves=np.arange(n_blocks) if keep else None,
    )
    tracker = tracker or tracker_curves(sky, study, every=blocks_of.members, engine=engine)
    orientation, gross, net = tracker.orientation, tracker.power, tracker.net
    incident = tracker.incident
    if incident is None:
        incident = engines.poa(sky, *orientation[:2], incident=True, normal=orientation[2])
    tracker_poa = energy(incident, sky.step_hours)
    trackers = engines.curve_metrics(
        np.concatenate([gross, net]),
        loads,
        sky.step_hours,
        contiguous=True,
        engine=engine,
        load_shape=None if shape is None else np.concatenate([shape, shape]),
    )

    def per_design(twofold_values, flat_values, tracker_values):
        return np.stack(
            [
                flat_values,
                twofold_values.reshape(n_blocks, n_loads),
                tracker_values[:n_blocks],
                tracker_values[n_blocks:],
            ],
            axis=-1,
        )

    hours = per_design(twofold.t_solar[:, own, 0], flat.t_solar[:, 0], trackers.t_solar[:, 0])
    served = None
    if shape is not None:
        # A load profile's served energy integrates P_load(t) over the solar-powered time: from the
        # curves the rows' t_solar were reduced from.
        step = sky.step_hours
        twofold_served = np.stack(
            [
                energy_served(
                    twofold.power[index::n_loads, own],
                    load,
                    shape,
                    step,
                    twofold.t_solar[index::n_loads, own, 0],
                )
                for index, load in enumerate(loads)
            ],
            1,
        )
        served = np.stack(
            [
                energy_served(flat.power[:, 0], loads, shape, step, flat.t_solar[:, 0]),
                twofold_served,
                energy_served(gross, loads, shape, step, trackers.t_solar[:n_blocks, 0]),
                energy_served(net, loads, shape, step, trackers.t_solar[n_blocks:, 0]),
            ],
            axis=-1,
        )
    fold = np.stack(
        [
            np.full((n_blocks, n_loads), FLAT_FOLD_ANGLE),
            fold_angles[chosen],
            np.full((n_blocks, n_loads), np.nan),
            np.full((n_blocks, n_loads), np.nan),
        ],
        axis=-1,
    )
    columns = metric_columns(
        hours,
        per_design(
            twofold.t_solar_contiguous[:, own, 0],
            flat.t_solar_contiguous[:, 0],
            trackers.t_solar_contiguous[:, 0],
        ),
        per_design(
            twofold.energy[:, own],
            np.repeat(flat.energy, n_loads, axis=1),
            np.repeat(trackers.energy, n_loads, axis=1),
        ),
        per_design(
            twofold.peak[:, own],
            np.repeat(flat.peak, n_loads, axis=1),
            np.repeat(trackers.peak, n_loads, axis=1),
        ),
        loads[None, :, None],
        served,
    )
    # Every design here is wired as the study's circuit says: a load beyond the panel's reach, every one.
    reach = engines.electrical_for(electrical, sky.temp_air[0], sky.wind_ref).beyond_reach
    condition = np.array(
        ["; ".join(filter(None, (reach, day))) for day in sky.conditions()], dtype=object
    )
    drawn = (
        {}
        if not curves
        else {
            "curves": {
                "flat": flat.power[:, 0],
                **{
                    name: twofold.power[:, index].reshape(n_blocks, n_loads, -1)
                    for index, name in enumerate(outputs)
                },
            }
        }
    )
    return {
        "fold_angle_deg": fold,
        **columns,
        "poa_global_wh_m2": per_design(
            twofold.irradiation,
            np.repeat(flat.irradiation[:, None], n_loads, axis=1),
            np.repeat(np.r_[tracker_poa, tracker_poa][:, None], n_loads, axis=1),
        ),
        # A tracker whose drive costs more than it harvests says so where every table's note starts.
        "condition": design_condition(condition[:, None, None], columns["energy_harvested_wh"]),
        **drawn,
    }


@dataclass(frozen=True)
class DailyDesigns:
    """Each day's t_solar [h] and harvested energy [Wh] of every design, for statistics over days.

    Attributes
    ----------
    angles : numpy.ndarray
        The twofold panel's fold angles [deg], (n,): the study's grid, or those a search evaluated.
    twofold_h : numpy.ndarray
        (days, loads, n).
    twofold_wh : numpy.ndarray
        (days, n).
    flat_h, tracker_h, tracker_net_h : numpy.ndarray
        (days, loads); the tracker net of its own draw; the flat panel at the site's mounting.
    flat_wh, tracker_wh : numpy.ndarray
        (days,); the tracker's gross harvest.
    peak_power_flat_w : numpy.ndarray
        (days,) the flat panel's peak power [W].
    available : numpy.ndarray
        (days, steps) [W]: the tracker's power left for the load and a standby draw
        (:func:`standby_available`).
    tilts : numpy.ndarray or None
        With a search of the tilt too, each design's base tilt [deg], (n,); None: the site's.
    flat_tilted : tuple or None
        With a search of the tilt, the flat panel at the tilts it evaluated: ``(tilts (m,), hours
        (days, loads, m), energy (days, m))``.
    """

    angles: np.ndarray
    twofold_h: np.ndarray
    twofold_wh: np.ndarray
    flat_h: np.ndarray
    flat_wh: np.ndarray
    tracker_h: np.ndarray
    tracker_net_h: np.ndarray
    tracker_wh: np.ndarray
    available: np.ndarray
    peak_power_flat_w: np.ndarray
    tilts: np.ndarray | None = None
    flat_tilted: tuple | None = None


def daily_designs(parts, loads, engine: str = DEFAULT_ENGINE, search=None) -> DailyDesigns:
    """:class:`DailyDesigns` over chunks of days at one site (:func:`site_designs` of one site).

    Parameters
    ----------
    parts : sequence of (Blocks, Sky)
        Each chunk of :class:`Blocks` with its sky.
    loads : array_like
        (n_loads,) [W]; an infinite load carries nothing.
    engine : {'auto', 'numba', 'numpy'}
    search : callable, optional
        As :func:`site_designs`' (one site); default every angle of the study's grid.
    """
    n_blocks = sum(sky.n_blocks for _, sky in parts)
    return site_designs(
        parts, [range(n_blocks)], np.asarray(loads, dtype=float)[None], engine, search
    )[0]


def site_designs(parts, sites, loads, engine: str = DEFAULT_ENGINE, search=None) -> list:
    """:class:`DailyDesigns` of many sites over chunks of their days, every engine call over all of
    them (a map's batch of sites).

    Parameters
    ----------
    parts : sequence of (Blocks, Sky)
        Chunks of :class:`Blocks` with their skies, in order.
    sites : sequence of range
        Each site's blocks, consecutive over the chunks.
    loads : array_like
        (n_sites, n_loads) each site's loads [W]; an infinite load carries nothing.
    engine : {'auto', 'numba', 'numpy'}
    search : callable, optional
        ``search(parts, sites, loads, loadset, engine)`` -> per site ``(designs (n, 2) fold angle and
        base tilt, hours (days, loads, n), energy (days, n), flat)`` at the designs it chooses to
        evaluate (a search: :func:`foldopt.studies.site_search.fold_search`), ``loadset`` each
        block's site, ``flat`` None or the flat panel at tilts of its own (``tilts, hours,
        energy``); default every angle of the study's grid on every day at the site's tilt.

    Returns
    -------
    list of DailyDesigns
    """
    loads = np.asarray(loads, dtype=float)
    loadset = np.concatenate([np.full(len(blocks), site) for site, blocks in enumerate(sites)])
    study = parts[0][0].study
    if search is None:
        search = _every_angle
    searched = search(parts, sites, loads, loadset, engine)
    flat, flat_energy, flat_peak, tracker, available = [], [], [], [], []
    start = 0
    for chunk, sky in parts:
        rows = slice(start, start + sky.n_blocks)
        start = rows.stop
        metrics = engines.row_metrics(
            sky,
            rows=engines.PanelRows(
                np.arange(sky.n_blocks),
                engines.flat_orientation(chunk.tilt, chunk.azimuth),
                loadset=loadset[rows],
            ),
            loads=loads,
            electrical=chunk.options.electrical,
            outputs=("panel",),
            engine=engine,
        )
        flat.append(metrics.t_solar[:, 0])
        flat_energy.append(metrics.energy[:, 0])
        flat_peak.append(metrics.peak[:, 0])
        curves = tracker_curves(sky, study, engine=engine)
        both = engines.curve_metrics(
            curves.gross_and_net(),
            loads,
            sky.step_hours,
            np.concatenate([loadset[rows], loadset[rows]]),
            engine=engine,
        )
        tracker.append(
            (
                both.t_solar[: sky.n_blocks, 0],
                both.t_solar[sky.n_blocks :, 0],
                both.energy[: sky.n_blocks, 0],
            )
        )
        available.append(
            standby_available(curves.power, curves.draw, sky.lit, study.tracker.standby_w)
        )
    gross_h, net_h, gross_wh = (np.concatenate(values) for values in zip(*tracker, strict=True))
    flat, flat_energy, flat_peak, available = (
        values[0] if len(values) == 1 else np.concatenate(values)
        for values in (flat, flat_energy, flat_peak, available)
    )
    tilted = any(flat_tilted is not None for *_, flat_tilted in searched)
    return [
        DailyDesigns(
            points[:, 0],
            hours,
            energy,
            flat[days],
            flat_energy[days],
            gross_h[days],
            net_h[days],
            gross_wh[days],
            available[days],
            flat_peak[days],
            points[:, 1] if tilted else None,
            flat_tilted,
        )
        for days, (points, hours, energy, flat_tilted) in zip(
            map(_days, sites), searched, strict=True
        )
    ]


def _days(blocks):
    """A site's blocks as a slice where consecutive: a view of the days' arrays, not a copy."""
    if isinstance(blocks, range) and blocks.step == 1:
        return slice(blocks.start, blocks.stop)
    return blocks


def _every_angle(parts, sites, loads, loadset, engine):
    """Every angle of the study's grid on every day of each site: ``site_designs``' default search."""
    study = parts[0][0].study
    fold_angles = np.asarray(study.fold_angles.grid())
    tilt = np.concatenate([chunk.tilt for chunk, _ in parts])
    azimuth = np.concatenate([chunk.azimuth for chunk, _ in parts])
    requests = [
        (
            np.asarray(blocks),
            np.column_stack(
                [
                    fold_angles,
                    np.full(fold_angles.size, tilt[blocks[0]]),
                    np.full(fold_angles.size, azimuth[blocks[0]]),
                ]
            ),
        )
        for blocks in sites
    ]
    done = requested_hours(parts, requests, loads, loadset, engine=engine)
    return [
        (points, hours.transpose(0, 2, 1), energy, None)
        for (_, points), (hours, energy) in zip(requests, done, strict=True)
    ]


def design_hours(
    parts,
    points,
    loads,
    flat: bool = False,
    engine: str = DEFAULT_ENGINE,
    with_energy: bool = False,
):
    """Each day's t_solar [h] of arbitrary designs: a fold angle, base tilt and base azimuth each,
    for the search of :func:`foldopt.studies.joint.optimize_plan`.

    Parameters
    ----------
    parts : sequence of (Blocks, Sky)
        Chunks of days (:meth:`Blocks.chunks`) with their skies.
    points : array_like
        (n, 3) fold angle, base tilt, base azimuth [deg] (the azimuth taken modulo 360).
    loads : array_like
        (n_loads,) [W].
    flat : bool
        The flat panel (the fold angle unused) with no connection: as the ``flat`` design.
    engine : {'auto', 'numba', 'numpy'}
    with_energy : bool
        Also each day's harvested energy.

    Returns
    -------
    numpy.ndarray
        (days, n, n_loads); with ``with_energy`` also (days, n) [Wh].
    """
    n_blocks = sum(sky.n_blocks for _, sky in parts)
    hours, energy = requested_hours(
        parts, [(np.arange(n_blocks), points)], loads, flat=flat, engine=engine
    )[0]
    return (hours, energy) if with_energy else hours


def requested_hours(
    parts,
    requests,
    loads,
    loadset=None,
    flat: bool = False,
    engine: str = DEFAULT_ENGINE,
    orientations=None,
) -> list:
    """Each day's t_solar [h] and harvested energy [Wh] of designs, each request on days of its
    own, every request of a chunk in as few engine calls as its memory bound allows.

    Parameters
    ----------
    parts : sequence of (Blocks, Sky)
        Chunks of :class:`Blocks` with their skies, in order.
    requests : sequence of (array_like, array_like)
        ``(blocks, points)``: the blocks (indices over the chunks in order) and the designs,
        (n, 3) fold angle, base tilt, base azimuth [deg] (the azimuth taken modulo 360).
    loads : array_like
        (n_loads,) [W], or (n_sets, n_loads) sets chosen by ``loadset``.
    loadset : array_like of int, optional
        (n_blocks,) each block's set of loads; default the first.
    flat : bool
        The flat panel (the fold angle unused) with no connection: as the ``flat`` design.
    engine : {'auto', 'numba', 'numpy'}
    orientations : sequence of array_like, optional
        Per request, its designs' sub-panel orientations, (n, 4) as
        :func:`foldopt.engine.evaluation.fold_orientations` gives them, where the caller has them
        (a search's grid, worked out once); default worked out here.

    Returns
    -------
    list of (numpy.ndarray, numpy.ndarray)
        Per request, ``hours`` (blocks, n, n_loads) and ``energy`` (blocks, n).
    """
    loads = np.atleast_2d(np.asarray(loads, dtype=float))
    study, options = parts[0][0].study, parts[0][0].options
    output = "panel" if flat else study.connection
    requests = [
        (np.asarray(blocks, dtype=np.int64), np.asarray(points, dtype=float).reshape(-1, 3))
        for blocks, points in requests
    ]
    loadset = (
        np.zeros(sum(sky.n_blocks for _, sky in parts), dtype=np.int64)
        if loadset is None
        else loadset
    )
    # Every request's orientations in one call.
    every = np.concatenate([points for _, points in requests])
    if orientations is not None:
        table = np.concatenate([np.asarray(given, dtype=float) for given in orientations])
    elif flat:
        table = engines.flat_orientation(every[:, 1], every[:, 2] % 360.0)
    else:
        table = engines.design_orientations(
            study.geometry, every[:, 0], every[:, 1], every[:, 2] % 360.0
        )
    tables = np.split(table, np.cumsum([points.shape[0] for _, points in requests])[:-1])
    out = [
        (
            np.empty((blocks.size, points.shape[0], loads.shape[1])),
            np.empty((blocks.size, points.shape[0])),
        )
        for blocks, points in requests
    ]
    start = 0
    for _, sky in parts:
        stop = start + sky.n_blocks
        # Pieces (request, its blocks in the chunk, points): each within the memory bound, gathered
        # into calls that stay within it too.
        calls, size = [[]], 0
        for k, (blocks, points) in enumerate(requests):
            inside = np.flatnonzero((blocks >= start) & (blocks < stop))
            per = max(1, CHUNK_ROW_LOADS // max(inside.size * loads.shape[1], 1))
            for first in range(0, points.shape[0] if inside.size else 0, per):
                piece = (k, inside, slice(first, min(first + per, points.shape[0])))
                cost = inside.size * (piece[2].stop - first) * loads.shape[1]
                if size + cost > CHUNK_ROW_LOADS and calls[-1]:
                    calls.append([])
                    size = 0
                calls[-1].append(piece)
                size += cost
        for call in filter(None, calls):
            counts = [piece.stop - piece.start for _, _, piece in call]
            offsets = np.cumsum([0, *counts[:-1]])
            orientation = np.concatenate([tables[k][piece] for k, _, piece in call])
            blocks = [requests[k][0][inside] for k, inside, _ in call]
            row_block = np.concatenate(
                [np.repeat(b - start, n) for b, n in zip(blocks, counts, strict=True)]
            )
            row_orientation = np.concatenate(
                [
                    offset + np.tile(np.arange(n), b.size)
                    for b, n, offset in zip(blocks, counts, offsets, strict=True)
                ]
            )
            metrics = engines.row_metrics(
                sky,
                rows=engines.PanelRows(
                    row_block, orientation, row_orientation, np.take(loadset, start + row_block)
                ),
                loads=loads,
                electrical=options.electrical,
                outputs=(output,),
                engine=engine,
            )
            position = 0
            for (k, inside, piece), b, n in zip(call, blocks, counts, strict=True):
                rows = slice(position, position + b.size * n)
                position = rows.stop
                inside = _consecutive(inside)
                out[k][0][inside, piece] = metrics.t_solar[rows, 0].reshape(b.size, n, -1)
                out[k][1][inside, piece] = metrics.energy[rows, 0].reshape(b.size, n)
        start = stop
    return out


def _consecutive(indices):
    """Ascending indices as a slice where they are consecutive (a map's site's days), so that
    values are written into their place without an index array; else as they are."""
    if indices.size and indices[-1] - indices[0] == indices.size - 1:
        return slice(int(indices[0]), int(indices[-1]) + 1)
    return indices
