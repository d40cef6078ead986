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
- the trackers' orientation, power and own draw (:func:`sky_tracker_power`,
  :func:`sky_tracker_draw`) and what a standby draw leaves (:func:`standby_available`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from foldopt.engine import rows as engines
from foldopt.inputs.study import Study
from foldopt.engine.metrics import design_condition, energy, energy_served, metric_columns
from foldopt.engine.sky import Sky, build_sky
from foldopt.physics.trackers import TrackerDrive, TrackerOptions, tracker_draw, tracker_orientation

DESIGNS = ("flat", "twofold", "tracker", "tracker-net")
#: Rows (blocks x fold angles) x loads of one engine call: bounds the memory of a chunk.
CHUNK_ROW_LOADS = 4_000_000
#: Time steps of the blocks of one chunk's sky.
CHUNK_STEPS = 1_100_000


def setup_key(study: Study) -> str:
    """What the blocks of one engine call share, as sorted JSON: everything but the site, the date and
    the load (and the panel's orientation, which follows the site).

    Parameters
    ----------
    study : Study
    """
    data = study.model_dump(mode="json", exclude={"site", "date", "p_load", "name", "description"})
    data["panel"] = {k: v for k, v in data["panel"].items() if k not in ("tilt", "azimuth")}
    return json.dumps(data, sort_keys=True)


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
        steps=tracker.steps, angular_field=tracker.angular_field,
        step_offsets_h=tuple(tracker.step_offsets_h or TrackerOptions().step_offsets_h),
        axis_tilt=tracker.axis_tilt, axis_azimuth=tracker.axis_azimuth, max_angle=tracker.max_angle,
        backtrack=tracker.backtrack, gcr=tracker.gcr,
    )
    return tracker_orientation(
        model or tracker.model, sky.solar_zenith, sky.solar_azimuth, sky.hour_angle, sky.declination,
        np.asarray(sky.latitude)[:, None], options, sky.sun_vector,
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
    tilt, azimuth, normal = orientation
    return engines.panel_power(sky, study, engines.poa(sky, tilt, azimuth, normal=normal))


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
    return np.where(lit, gross - (draw - np.where(lit, standby_w, 0.0)), 0.0)


def sky_tracker_draw(sky: Sky, study: Study, orientation, every: int = 1) -> np.ndarray:
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
    """
    tracker = study.tracker
    drive = TrackerDrive(standby_w=tracker.standby_w, drive=tracker.drive, wh_per_degree=tracker.wh_per_degree)
    shared = slice(None, None, every)
    draw = tracker_draw(orientation[2][shared], sky.lit[shared], sky.step_hours, drive)
    return np.repeat(draw, every, axis=0) if every > 1 else draw


@dataclass(frozen=True)
class Blocks:
    """Blocks that share one setup (:func:`setup_key`): the study's settings at each (site, date),
    and each block's flat panel orientation.

    Parameters
    ----------
    study : Study
        The shared settings (resolved).
    sites, dates : tuple
        Each block's site and local date.
    tilt, azimuth : numpy.ndarray
        Each block's flat panel [deg], (n_blocks,).
    member : numpy.ndarray, optional
        With a cloud ensemble (``weather.members``), each block's member (n_blocks,): a day's
        members are consecutive blocks.
    """

    study: Study
    sites: tuple
    dates: tuple
    tilt: np.ndarray
    azimuth: np.ndarray
    member: np.ndarray | None = None

    @property
    def members(self) -> int:
        """Members of the cloud ensemble (1 without one)."""
        weather = self.study.weather
        return weather.members if weather is not None and weather.members else 1

    @classmethod
    def of(cls, studies) -> Blocks:
        """One block per study (its site, date and panel).

        Parameters
        ----------
        studies : sequence of Study
            Of one setup; the first gives the shared settings.
        """
        resolved = [s.resolved() for s in studies]
        return cls(resolved[0], tuple(s.site for s in resolved), tuple(s.date for s in resolved),
                   np.array([s.panel.tilt for s in resolved]), np.array([s.panel.azimuth for s in resolved]))

    @classmethod
    def of_dates(cls, study: Study, dates) -> Blocks:
        """The days of one study at its own site.

        Parameters
        ----------
        study : Study
        dates : sequence of datetime.date
        """
        study = study.resolved()
        members = study.weather.members if study.weather is not None and study.weather.members else 1
        dates = tuple(date for date in dates for _ in range(members))  # a day's members together
        count = len(dates)
        member = np.tile(np.arange(members), count // members) if members > 1 else None
        return cls(study, (study.site,) * count, dates, np.full(count, study.panel.tilt),
                   np.full(count, study.panel.azimuth), member)

    def __len__(self) -> int:
        return len(self.dates)

    def __getitem__(self, part: slice) -> Blocks:
        return Blocks(self.study, self.sites[part], self.dates[part], self.tilt[part], self.azimuth[part],
                      None if self.member is None else self.member[part])

    def sky(self) -> Sky:
        """The blocks' :class:`foldopt.engine.sky.Sky` (:func:`foldopt.engine.sky.build_sky`)."""
        return build_sky(self.study, self.sites, self.dates, self.member)

    def chunks(self, n_loads: int):
        """Slices of blocks whose rows x loads and time steps stay within the chunk bounds.

        Parameters
        ----------
        n_loads : int
            Loads per row.

        Returns
        -------
        list of slice
            Consecutive, covering every block; at least one block each.
        """
        per_block = len(self.study.fold_angles.grid()) * max(n_loads, 1)
        n_steps = round(24 * 60 / self.study.step_min)
        size = max(1, min(CHUNK_ROW_LOADS // per_block, CHUNK_STEPS // n_steps))
        # A day's members stay in one chunk: they share its sun (foldopt.engine.sky.build_sky).
        size = max(self.members, size // self.members * self.members)
        return [slice(start, min(start + size, len(self))) for start in range(0, len(self), size)]


def fold_hours(sky: Sky, blocks: Blocks, loads, engine: str = "numba"):
    """t_solar [h] of every block's twofold panel at every angle of the grid, for every load.

    Parameters
    ----------
    sky : Sky
        The blocks' sky.
    blocks : Blocks
    loads : array_like
        (n_loads,) [W].
    engine : {'numba', 'numpy'}

    Returns
    -------
    angles : numpy.ndarray
        The study's fold-angle grid [deg], (n_angles,).
    hours : numpy.ndarray
        (n_blocks, n_angles, n_loads).
    energy : numpy.ndarray
        Harvested energy [Wh], (n_blocks, n_angles).
    """
    study = blocks.study
    angles = np.asarray(study.fold_angles.grid())
    orientation = engines.fold_orientations(study, blocks.tilt, blocks.azimuth, angles)
    rows = np.repeat(np.arange(sky.n_blocks), angles.size)
    metrics = engines.row_metrics(sky, study, rows, orientation.reshape(-1, 4), loads, outputs=(study.connection,),
                                  engine=engine)
    return (angles, metrics.t_solar.reshape(sky.n_blocks, angles.size, -1),
            metrics.energy.reshape(sky.n_blocks, angles.size))


def design_metrics(sky: Sky, blocks: Blocks, loads, angles, chosen, engine: str) -> dict:
    """Metrics of every design per block and load, each (n_blocks, n_loads, 4 designs): the twofold
    panel at grid index ``chosen`` (n_blocks, n_loads), the flat panel, the tracker gross and net.

    Parameters
    ----------
    sky : Sky
    blocks : Blocks
    loads : numpy.ndarray
        (n_loads,) [W].
    angles : numpy.ndarray
        The fold-angle grid [deg].
    chosen : numpy.ndarray of int
        (n_blocks, n_loads) index into ``angles`` of the twofold panel's angle.
    engine : {'numba', 'numpy'}

    Returns
    -------
    dict of numpy.ndarray
        ``fold_angle_deg``, the :func:`foldopt.engine.metrics.metric_columns`, ``poa_kwh_m2`` (incident
        irradiation [kWh/m^2]) and ``condition`` (:func:`foldopt.engine.metrics.design_condition`), each
        (n_blocks, n_loads, 4) in the order of :data:`DESIGNS`.
    """
    study, blocks_of = blocks.study, blocks
    n_blocks, n_loads = sky.n_blocks, loads.size
    tilt, azimuth = blocks.tilt, blocks.azimuth
    every = engines.fold_orientations(study, tilt, azimuth, angles)
    blocks = np.repeat(np.arange(n_blocks), n_loads)
    # One row per block and load, at that load's angle, with the load alone.
    twofold = engines.row_metrics(sky, study, blocks, every[blocks, chosen.ravel()], loads[:, None],
                                  np.tile(np.arange(n_loads), n_blocks), outputs=(study.connection,),
                                  contiguous=True, engine=engine)
    flat = engines.row_metrics(sky, study, np.arange(n_blocks), engines.flat_orientation(tilt, azimuth), loads,
                               outputs=("panel",), contiguous=True, engine=engine)
    orientation = sky_tracker_orientation(sky, study)
    gross = sky_tracker_power(sky, study, orientation)
    tracker_poa = energy(engines.poa(sky, *orientation[:2], incident=True, normal=orientation[2]), sky.step_hours)
    net = gross - sky_tracker_draw(sky, study, orientation, every=blocks_of.members)
    shape = sky.load_shape
    trackers = engines.curve_metrics(np.concatenate([gross, net]), loads, sky.step_hours, contiguous=True,
                                     engine=engine,
                                     load_shape=None if shape is None else np.concatenate([shape, shape]))

    def per_design(twofold_values, flat_values, tracker_values):
        return np.stack([flat_values, twofold_values.reshape(n_blocks, n_loads), tracker_values[:n_blocks],
                         tracker_values[n_blocks:]], axis=-1)

    hours = per_design(twofold.t_solar[:, 0, 0], flat.t_solar[:, 0], trackers.t_solar[:, 0])
    served = None
    if shape is not None:
        # A load profile's served energy integrates P_load(t) over the solar-powered time: from the curves.
        step = sky.step_hours
        curves = [engines.powers(sky, study, every[np.arange(n_blocks), chosen[:, index]], series=study.switch_series
                                 )[0][study.connection] for index in range(n_loads)]
        twofold_served = np.stack([energy_served(curve, load, shape, step, twofold.t_solar[index::n_loads, 0, 0])
                                   for index, (curve, load) in enumerate(zip(curves, loads, strict=True))], 1)
        flat_curve = engines.powers(sky, study, engines.flat_orientation(tilt, azimuth), series=False)[0]["panel"]
        served = np.stack([energy_served(flat_curve, loads, shape, step, flat.t_solar[:, 0]), twofold_served,
                           energy_served(gross, loads, shape, step, trackers.t_solar[:n_blocks, 0]),
                           energy_served(net, loads, shape, step, trackers.t_solar[n_blocks:, 0])], axis=-1)
    fold = np.stack([np.full((n_blocks, n_loads), 180.0), angles[chosen], np.full((n_blocks, n_loads), np.nan),
                     np.full((n_blocks, n_loads), np.nan)], axis=-1)
    columns = metric_columns(
        hours,
        per_design(twofold.t_solar_contiguous[:, 0, 0], flat.t_solar_contiguous[:, 0],
                   trackers.t_solar_contiguous[:, 0]),
        per_design(twofold.energy[:, 0], np.repeat(flat.energy, n_loads, axis=1),
                   np.repeat(trackers.energy, n_loads, axis=1)),
        per_design(twofold.peak[:, 0], np.repeat(flat.peak, n_loads, axis=1),
                   np.repeat(trackers.peak, n_loads, axis=1)),
        loads[None, :, None],
        served,
    )
    return {
        "fold_angle_deg": fold,
        **columns,
        "poa_kwh_m2": per_design(twofold.irradiation, np.repeat(flat.irradiation[:, None], n_loads, axis=1),
                                 np.repeat(np.r_[tracker_poa, tracker_poa][:, None], n_loads, axis=1)) / 1000.0,
        # A tracker whose drive costs more than it harvests says so where every table's note starts.
        "condition": design_condition(sky.conditions()[:, None, None], columns["energy_harvested_wh"]),
    }


@dataclass(frozen=True)
class DailyDesigns:
    """Each day's t_solar [h] and harvested energy [Wh] of every design, for statistics over days.

    Attributes
    ----------
    angles : numpy.ndarray
        The fold-angle grid [deg], (n_angles,).
    twofold_h : numpy.ndarray
        (days, loads, angles).
    twofold_wh : numpy.ndarray
        (days, angles).
    flat_h, tracker_h, tracker_net_h : numpy.ndarray
        (days, loads); the tracker net of its own draw.
    flat_wh, tracker_wh : numpy.ndarray
        (days,); the tracker's gross harvest.
    available : numpy.ndarray
        (days, steps) [W]: the tracker's power left for the load and a standby draw
        (:func:`standby_available`).
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


def daily_designs(parts, loads, engine: str = "numba", fold=None) -> DailyDesigns:
    """:class:`DailyDesigns` over chunks of days.

    Parameters
    ----------
    parts : sequence of (Blocks, Sky)
        Each chunk of :class:`Blocks` with its sky.
    loads : array_like
        (n_loads,) [W]; an infinite load carries nothing.
    engine : {'numba', 'numpy'}
    fold : callable, optional
        ``fold(parts, loads, engine)`` -> the twofold panel's ``(angles, hours (days, loads, angles),
        energy (days, angles))`` at the angles it chooses to evaluate (a search:
        :func:`foldopt.studies.joint.fold_search`); default every angle of the study's grid.
    """
    twofold, harvest, flat, flat_energy, tracker, available = [], [], [], [], [], []
    if fold is not None:
        angles, searched_hours, searched_energy = fold(parts, loads, engine)
    for chunk, sky in parts:
        study = chunk.study
        if fold is None:
            angles, hours, energy_harvested_wh = fold_hours(sky, chunk, loads, engine)
            twofold.append(hours)
            harvest.append(energy_harvested_wh)
        metrics = engines.row_metrics(sky, study, np.arange(sky.n_blocks), engines.flat_orientation(
            chunk.tilt, chunk.azimuth), loads, outputs=("panel",), engine=engine)
        flat.append(metrics.t_solar[:, 0])
        flat_energy.append(metrics.energy[:, 0])
        orientation = sky_tracker_orientation(sky, study)
        gross = sky_tracker_power(sky, study, orientation)
        draw = sky_tracker_draw(sky, study, orientation)
        both = engines.curve_metrics(np.concatenate([gross, gross - draw]), loads, sky.step_hours, engine=engine)
        tracker.append((both.t_solar[:sky.n_blocks, 0], both.t_solar[sky.n_blocks:, 0], both.energy[:sky.n_blocks, 0]))
        available.append(standby_available(gross, draw, sky.lit, study.tracker.standby_w))
    gross_h, net_h, gross_wh = (np.concatenate(values) for values in zip(*tracker, strict=True))
    if fold is None:
        searched_hours, searched_energy = np.concatenate(twofold).transpose(0, 2, 1), np.concatenate(harvest)
    return DailyDesigns(angles, searched_hours, searched_energy, np.concatenate(flat), np.concatenate(flat_energy),
                        gross_h, net_h, gross_wh, np.concatenate(available))


def design_hours(parts, points, loads, flat: bool = False, engine: str = "numba", with_energy: bool = False):
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
    engine : {'numba', 'numpy'}
    with_energy : bool
        Also each day's harvested energy.

    Returns
    -------
    numpy.ndarray
        (days, n, n_loads); with ``with_energy`` also (days, n) [Wh].
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    loads = np.asarray(loads, dtype=float)
    study = parts[0][0].study
    tilt, azimuth = points[:, 1], points[:, 2] % 360.0
    if flat:
        orientation, output = engines.flat_orientation(tilt, azimuth), "panel"
    else:
        orientation, output = _orientations(study, points[:, 0], tilt, azimuth), study.connection
    days, harvest = [], []
    for _, sky in parts:
        per_chunk = max(1, CHUNK_ROW_LOADS // max(sky.n_blocks * loads.size, 1))
        hours = np.empty((sky.n_blocks, points.shape[0], loads.size))
        energy = np.empty((sky.n_blocks, points.shape[0]))
        for start in range(0, points.shape[0], per_chunk):
            piece = slice(start, min(start + per_chunk, points.shape[0]))
            count = piece.stop - piece.start
            rows = np.repeat(np.arange(sky.n_blocks), count)
            metrics = engines.row_metrics(sky, study, rows, orientation[piece], loads, outputs=(output,),
                                          engine=engine, row_orientation=np.tile(np.arange(count), sky.n_blocks))
            hours[:, piece] = metrics.t_solar[:, 0].reshape(sky.n_blocks, count, loads.size)
            energy[:, piece] = metrics.energy[:, 0].reshape(sky.n_blocks, count)
        days.append(hours)
        harvest.append(energy)
    return (np.concatenate(days), np.concatenate(harvest)) if with_energy else np.concatenate(days)


def _orientations(study: Study, fold_angle, tilt, azimuth) -> np.ndarray:
    """(n, 4) the sub-panels' orientation of each design: one geometry call per distinct base."""
    bases = np.stack([tilt, azimuth], axis=-1)
    unique, inverse = np.unique(bases, axis=0, return_inverse=True)
    inverse = np.ravel(inverse)
    orientation = np.empty((fold_angle.size, 4))
    for index, (base_tilt, base_azimuth) in enumerate(unique):
        take = inverse == index
        orientation[take] = engines.fold_orientations(study, [base_tilt], [base_azimuth], fold_angle[take])[0]
    return orientation
