"""The compiled engine's inputs and outputs as named records, declared once.

:func:`foldopt.engine.kernel.fold_rows` takes a day's light (:class:`SkyArrays`), the panels
(:class:`Rows`), the electrical side (:class:`Tables`), the loads (:class:`Loads`), and writes
:class:`Outputs` with per-chunk :class:`Scratch`; :func:`foldopt.engine.curve_reduction.curve_rows` takes the
last three. numba takes these module-level named tuples as arguments (and caches functions typed by
them), so adding an input is a field here and the line of :mod:`foldopt.engine.evaluation` that fills it.
Every field is an array, a float, an int or a bool, always of the same type, so that one compiled
specialisation serves every call. The rows go to threads in chunks (:func:`in_chunks`), each
chunk a call of a compiled function that releases the GIL (``_chunk_rows``, ``_chunk_curves``)
with its own :class:`Scratch`.
"""

from __future__ import annotations

import itertools
from typing import NamedTuple

import numpy as np

from foldopt.threads import submit

CHUNKS_PER_THREAD = 8  # rows are handed out in chunks: enough for balance, few scratch buffers
TABLE_BLOCK = 256  # steps whose tables' coordinates are worked out at once: they stay in L1
WALK_BLOCK = 16  # steps a block of a day's walk over its loads (a multiple of it is TABLE_BLOCK)


class SkyArrays(NamedTuple):
    """The light of every block of a sky, laid out along the steps, and how the beam is taken.

    Attributes
    ----------
    sun : (n_blocks, 3, n_steps) float
        Unit sun vectors (east, north, up).
    paper_sun : (n_blocks, 4, n_steps) float
        cos(zenith), sin(zenith), sin(azimuth), cos(azimuth) for Eq. 5 (a placeholder (1, 4, 1)
        unless ``paper``).
    beam : (n_blocks, n_steps) float
        Direct normal irradiance [W/m^2].
    terms : (n_blocks, 4, n_steps) float
        Diffuse terms (isotropic, circumsolar, horizon, ground) of
        :func:`foldopt.physics.irradiance.sky_diffuse_terms`; (n_blocks, 0, n_steps) for beam only.
    span : (n_blocks, 2) int
        First and last step to walk: the steps with any light and one dark step either side. The
        dark steps before and after hold zero power, so they join the half-steps held at the ends
        of the day.
    step_table, step_weight : (n_blocks, n_steps) or (n_blocks, 1) int and float
        The electrical table set of each step (or of each block): its cells' air temperature lies
        between set ``t`` and ``t + 1``, at ``weight`` of the way (0: set ``t``).
    paper : bool
        The beam's incidence by Shin et al.'s Eq. 5 (paper mode) instead of the angle of incidence.
    iam_model : int
        The beam's incidence-angle modifier (:data:`foldopt.engine.incidence.IAM_NONE` ...).
    iam_params : (3,) float
        Its parameters (:func:`foldopt.engine.incidence.iam_factor`).
    """

    sun: np.ndarray
    paper_sun: np.ndarray
    beam: np.ndarray
    terms: np.ndarray
    span: np.ndarray
    step_table: np.ndarray
    step_weight: np.ndarray
    paper: bool
    iam_model: int
    iam_params: np.ndarray


class Rows(NamedTuple):
    """The rows: each a block of the sky seen by one panel's two sub-panels.

    Attributes
    ----------
    block, loadset : (n_rows,) int
        Each row's block and set of loads.
    normal : (n_rows, 2, 3) float
        East and west sub-panel normals.
    paper : (n_rows, 2, 4) float
        cos(tilt), sin(tilt), cos(azimuth), sin(azimuth) per sub-panel (read in paper mode).
    sky_view : (n_rows, 2, 2) float
        Per sub-panel, the factors of the isotropic and the horizon-band diffuse terms:
        (1 + cos tilt) / 2 and sin tilt, less what the site's horizon hides
        (:func:`foldopt.physics.horizon.sky_view_factors`).
    curve : (n_rows,) int
        Where each row's power curves go in :attr:`Outputs.power`; -1 for a row whose curves are
        not kept.
    """

    block: np.ndarray
    normal: np.ndarray
    paper: np.ndarray
    sky_view: np.ndarray
    loadset: np.ndarray
    curve: np.ndarray


class Tables(NamedTuple):
    """The electrical side: the tables (stacked over table sets, one per air temperature), the
    circuit as built, and the outputs to evaluate.

    Attributes
    ----------
    subpanel, parallel, series : float arrays
        Per set: a sub-panel's power [W] on sqrt-spaced irradiance nodes, and the parallel and
        series pairs as fractions of the two maxima over the stronger irradiance and the
        weaker/stronger ratio (:class:`foldopt.engine.electrical.Electrical`); placeholders for a
        model without I-V curve (and ``series`` where no series power is asked).
    power_terms : (n_sets, 2) float
        Per set, a model without I-V curve's sub-panel power ``a E + q E^2`` as ``(a, q)``
        [W/(W/m^2)], [W/(W/m^2)^2] (:meth:`foldopt.physics.pvmodel.PVModel.power_terms`); (0, 2)
        with tables.
    panel_scale : float
        Panel area / sub-panel area.
    bypass, switch_series : bool
        The series pair never below its stronger sub-panel (a bypass diode); switching may also take
        the series pair.
    converter_efficiency : float
        The independent connection's converters' efficiency [-].
    connections : (n_conn,) int
        Codes of the outputs to evaluate (:data:`foldopt.engine.kernel.EAST` ...).
    as_built : bool
        The circuit as built (:mod:`foldopt.engine.as_built`), not Shin et al.'s ideal parts.
    direct, switch_table : bool
        As built: direct coupling at the load's voltage; switching has a table of its own (a
        switch resistance).
    alone, panel, switching : float arrays
        As built, stacked as the other tables: a sub-panel's and the whole panel's power delivered
        at the load's voltage (direct coupling), and switching as a fraction of the two maxima
        (placeholders where unused).
    converter : (n,) float
        The converter's delivered power / rating (:func:`foldopt.physics.converter.delivered_table`).
    converter_rating : float
        The converter's rating [W]; 0 for an ideal converter.
    """

    subpanel: np.ndarray
    parallel: np.ndarray
    series: np.ndarray
    power_terms: np.ndarray
    panel_scale: float
    bypass: bool
    switch_series: bool
    converter_efficiency: float
    connections: np.ndarray
    as_built: bool
    direct: bool
    switch_table: bool
    alone: np.ndarray
    panel: np.ndarray
    switching: np.ndarray
    converter: np.ndarray
    converter_rating: float


class Loads(NamedTuple):
    """The loads and how a day's power curve is held against them.

    Attributes
    ----------
    p_load : (n_loadsets, n_loads) float
        Loads [W], ascending in each set.
    profile : (n_blocks, n_steps) float
        With ``use_profile``, each block's (or curve's) load profile [W]: the loads are then its
        scales (one row (1, 1) without).
    use_profile : bool
    contiguous : bool
        Whether to track the longest contiguous interval too.
    step_hours : float
        Step length [h].
    """

    p_load: np.ndarray
    profile: np.ndarray
    use_profile: bool
    contiguous: bool
    step_hours: float


class Outputs(NamedTuple):
    """What the kernels write, per row, connection and load.

    Attributes
    ----------
    t_solar, t_solar_contiguous : (n_rows, n_conn, n_loads) float
        t_solar and its longest contiguous interval [h] (the latter (1, n_conn, n_loads) unless
        ``contiguous``).
    energy, peak : (n_rows, n_conn) float
        Energy [Wh] and peak power [W].
    irradiation : (n_rows,) float
        Incident plane-of-array irradiation [Wh/m^2] (before the incidence-angle modifier), the
        mean of the two (equal) sub-panels; empty for given power curves.
    power : (n_curves, n_conn, n_steps) float
        The power [W] at every step of the rows whose curves are kept (:attr:`Rows.curve`), the
        curves the metrics were reduced from (zero outside the lit span); (0, n_conn, 0) for none.
    """

    t_solar: np.ndarray
    t_solar_contiguous: np.ndarray
    energy: np.ndarray
    peak: np.ndarray
    irradiation: np.ndarray
    power: np.ndarray


class Scratch(NamedTuple):
    """Working arrays of each chunk of rows (:func:`allocate`): each field's first axis is the
    chunk, and a chunk's own record (:func:`in_chunks`) holds the rest. Every value is written
    before it is read (a row clears or overwrites what it uses), so a chunk's arrays hold
    whatever the last call left: they live in the calling thread's workspace
    (:func:`foldopt.threads.workspace`), each chunk's fields together on cache lines of their
    own, so that two threads' chunks never write to one line.

    Attributes
    ----------
    east, west : (n_steps,) float
        Each sub-panel's irradiance [W/m^2] (the beam alone while the incidence-angle modifier
        waits; as sqrt(E / E_max), the tables' coordinate, with tables).
    incident : (n_steps,) float
        The two sub-panels' mean incident irradiance before the modifier [W/m^2].
    diffuse_east, diffuse_west : (n_steps,) float
        Each sub-panel's diffuse irradiance while the beam waits for the modifier [W/m^2].
    power : (n_conn, n_steps) float
        Every asked connection's power of the row [W].
    above, whole : (n_loads,) and (n_loads + 1,) float
        A day's reduction: the time each load spends inside a segment's range, and the segments'
        lengths by how many loads lie below them (:func:`foldopt.engine.curve_reduction.day_metrics`).
    run : (n_loads or 1, 2) float
        The current and the longest run of each load (``contiguous``).
    nodes, weights : (3, TABLE_BLOCK) uint64 and (4, TABLE_BLOCK) float
        The tables' coordinates of a block of steps (:func:`foldopt.engine.kernel._switching_row`):
        each sub-panel's node below its irradiance and the pair table's node below both, and
        where each lies between its node and the next.
    low, high : (n_steps // WALK_BLOCK + 1,) float
        The lowest and the highest power [W] of each block of :data:`WALK_BLOCK` steps from the
        first step walked (:func:`foldopt.engine.curve_reduction.blocked_day`).
    held : (n_steps + 1,) float
        ``held[k]``: the length of ``k + 1`` steps [h], as ``k`` additions of the step to itself.
    """

    east: np.ndarray
    west: np.ndarray
    incident: np.ndarray
    diffuse_east: np.ndarray
    diffuse_west: np.ndarray
    power: np.ndarray
    above: np.ndarray
    whole: np.ndarray
    run: np.ndarray
    nodes: np.ndarray
    weights: np.ndarray
    low: np.ndarray
    high: np.ndarray
    held: np.ndarray


def allocate(
    n_rows: int, n_conn: int, n_loads: int, n_steps: int, contiguous: bool, n_curves: int = 0
) -> tuple[Outputs, Scratch]:
    """Outputs (new arrays, the caller's) and per-chunk scratch (the calling thread's workspace,
    reused by its next call) of :func:`foldopt.engine.kernel.fold_rows` or
    :func:`foldopt.engine.curve_reduction.curve_rows`.

    Parameters
    ----------
    n_rows, n_conn, n_loads : int
        Rows, connections and loads per set.
    n_steps : int
        Steps per day for ``fold_rows``; 0 for ``curve_rows`` (which reads no irradiance).
    contiguous : bool
        Whether the longest contiguous interval is tracked.
    n_curves : int, default 0
        Rows whose power curves ``fold_rows`` keeps (:attr:`Rows.curve`).

    Returns
    -------
    Outputs, Scratch
        The scratch is valid until the calling thread's next call of this function.
    """
    from numba import get_num_threads

    chunks = max(1, min(n_rows, get_num_threads() * CHUNKS_PER_THREAD))
    shape = (n_rows, n_conn)
    out = Outputs(
        t_solar=np.empty(shape + (n_loads,)),
        t_solar_contiguous=np.zeros(shape + (n_loads,))
        if contiguous
        else np.zeros((1, n_conn, n_loads)),
        energy=np.empty(shape),
        peak=np.empty(shape),
        irradiation=np.empty(n_rows if n_steps else 0),
        power=np.zeros((n_curves, n_conn, n_steps if n_curves else 0)),
    )
    table_block, walk_blocks = (TABLE_BLOCK if n_steps else 0), n_steps // WALK_BLOCK + 1
    light = ((n_steps,), np.float64)
    return out, _scratch(
        chunks,
        (
            *(light,) * 5,
            ((n_conn if n_steps else 0, n_steps), np.float64),
            ((n_loads,), np.float64),
            ((n_loads + 1,), np.float64),
            ((n_loads if contiguous else 1, 2), np.float64),
            ((3, table_block), np.uint64),
            ((4, table_block), np.float64),
            ((walk_blocks,), np.float64),
            ((walk_blocks,), np.float64),
            ((n_steps + 1,), np.float64),
        ),
    )


def _scratch(chunks: int, fields) -> Scratch:
    """A :class:`Scratch` of ``chunks`` chunks in the calling thread's workspace, ``fields`` the
    (shape, dtype) of each field's chunk: each chunk's fields one after the other, each on a
    cache line of its own (:data:`foldopt.threads.ALIGN`), so the chunks' lines are apart."""
    from foldopt.threads import ALIGN, workspace

    offsets, strides, stride = [], [], 0
    for shape, dtype in fields:
        # C order within a chunk: each axis steps over the product of the later ones.
        steps = [np.dtype(dtype).itemsize]
        for size in reversed(shape):
            steps.insert(0, steps[0] * size)
        offsets.append(stride)
        strides.append((*steps[1:],))
        stride += -(-steps[0] // ALIGN) * ALIGN
    buffer = workspace(chunks * stride)
    return Scratch(
        *(
            np.ndarray((chunks, *shape), dtype, buffer, offset, (stride, *inner))
            for (shape, dtype), offset, inner in zip(fields, offsets, strides, strict=True)
        )
    )


def in_chunks(body, n_rows: int, scratch: Scratch | None, *records, n_chunks: int = 0) -> None:
    """``body(start, stop, *records, work)`` over rows ``0 .. n_rows - 1`` in chunks, one chunk's
    :class:`Scratch` each, on numba's number of threads, the calling thread one of them (without
    ``scratch``, ``body(start, stop, *records)`` over ``n_chunks`` chunks).

    ``body`` is compiled with ``nogil=True``, so the chunks run in parallel on Python threads.
    They did in a numba ``prange`` loop, whose compile took a fifth of the kernel's (some 7 s
    of ``fold_rows``' 25 s on 2 cores; ``python bench/startup.py --events sweep-weather``),
    for nothing the chunks need: they share no writes. Each thread takes the next chunk not
    taken until none is left; the calling thread takes chunks too rather than wait, so that a
    call wakes one thread fewer and is not woken at the end (the wake-ups of threads on a virtual
    machine are a pass's milliseconds' tenths).

    Parameters
    ----------
    body : numba dispatcher
        ``_chunk_rows``, ``_chunk_curves`` or :func:`foldopt.engine.storage_kernel._series_range`.
    n_rows : int
    scratch : Scratch or None
        Of every chunk (:func:`allocate`): its first axis is the chunk. Every chunk has ended
        when this returns or raises.
    *records
        The arguments of ``body`` between ``stop`` and the chunk's scratch.
    n_chunks : int
        The chunks, without ``scratch`` (:func:`foldopt.engine.storage_kernel.simulate_series`).
    """
    from numba import get_num_threads

    if scratch is not None:
        n_chunks = scratch.above.shape[0]
    per_chunk = (n_rows + n_chunks - 1) // n_chunks
    taken, errors, halted = itertools.count(), [], []

    def chunks() -> None:
        # ``next`` of a count is one step of C under the GIL: each chunk is taken once.
        for k in taken:
            if k >= n_chunks or halted:
                return
            stop = min((k + 1) * per_chunk, n_rows)
            if k * per_chunk >= stop:
                continue
            try:
                work = () if scratch is None else (Scratch(*(field[k] for field in scratch)),)
                body(k * per_chunk, stop, *records, *work)
            except Exception as error:  # the other chunks run on: raised once they all ended
                errors.append(error)
            except BaseException as error:  # an interrupt: no chunk is taken after it
                halted.append(error)
                return

    threads = min(get_num_threads(), n_chunks)
    others = submit(threads - 1, [chunks] * (threads - 1)) if threads > 1 else []
    chunks()
    # Every chunk ended before a chunk's error is raised: the scratch is the calling thread's
    # workspace, which its next call takes again.
    for done in others:
        done.result()
    if halted or errors:
        raise (halted or errors)[0]
