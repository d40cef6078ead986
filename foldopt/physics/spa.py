"""NREL's solar position algorithm, split into a part shared by every site and a per-site part.

This module runs NREL's SPA [1]_ through the step functions of ``pvlib.spa``, split in two so that
many days and sites are one array program (:func:`foldopt.physics.solarposition.solar_position_grid`):
the geocentric part, which depends on time only, runs once per UTC hour that any day touches and
is interpolated, as SPA itself interpolates it for sunrise and sunset [1]_ (Appendix A.2), and
gives the sun's direction once per UTC step; the topocentric part is a rotation of that direction
per site and step, in vector form (:func:`spa_solar_position`), and the refraction is applied at
every step: the sun's direction stays within 2e-6 deg of ``pvlib.solarposition.spa_python``
(except at SPA's refraction cut-off, 0.83 deg below the horizon).

Why not ``pvlib.solarposition.get_solarposition``: it evaluates every term of SPA at every step
of every site, so over many sites the sun would cost an order of magnitude more than the split
(``bench/solarposition.py``; its figures in docs/performance.rst, "The sun's position"). The
price of the split is a dependence on ``pvlib.spa``'s step functions, which are not pvlib's
public API: pyproject.toml pins pvlib to the releases in which they are unchanged (0.11 to 0.16,
by pvlib's source history; tested with 0.16.1), and tests/test_solarposition.py holds the split
to ``spa_python`` on random sites. A process that has called ``spa_python(how='numba')`` has
``pvlib.spa`` reloaded as scalar numba functions, and the split then raises ``TypeError``.

References
----------
.. [1] I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
   Solar Energy 76(5), 577-589, 2004 (NREL/TP-560-34302), Sec. 3 and Appendix A.
"""

from __future__ import annotations

import functools

import numpy as np

from foldopt.threads import submit

NS_PER_HOUR = 3_600_000_000_000  # [ns]
SPA_DELTA_T = 67.0  # [s], TT - UT1, pvlib's default for spa_python
#: Instants whose time-only terms are evaluated at once: the periodic terms' arrays (terms x
#: instants, a few MB) then stay in the processor's caches, which a long series' would not.
GEOCENTRIC_CHUNK = 8192


def spa_geocentric(unixtime, delta_t: float = SPA_DELTA_T) -> dict:
    """The time-only part of SPA [1]_ (Sec. 3.1-3.9, 3.12.1 and A.1) via ``pvlib.spa``.

    The steps of ``pvlib.spa.solar_position_numpy`` before its site enters.

    Parameters
    ----------
    unixtime : array_like
        UTC instants [s since 1970-01-01].
    delta_t : float, default :data:`SPA_DELTA_T`
        TT - UT1 [s].

    Returns
    -------
    dict of numpy.ndarray
        The geocentric right ascension ``alpha`` and declination ``delta`` [deg], the apparent
        sidereal time ``v`` [deg], the equatorial horizontal parallax ``xi`` [deg] and the equation
        of time ``eot`` [min].

    References
    ----------
    .. [1] I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
       Solar Energy 76(5), 577-589, 2004.
    """
    unixtime = np.asarray(unixtime, dtype=float)
    if unixtime.size <= GEOCENTRIC_CHUNK:
        return _geocentric(unixtime, delta_t)
    # Elementwise in time: a chunk's terms are its instants' bits whatever the chunk.
    parts = [
        _geocentric(unixtime.ravel()[at : at + GEOCENTRIC_CHUNK], delta_t)
        for at in range(0, unixtime.size, GEOCENTRIC_CHUNK)
    ]
    return {
        name: np.concatenate([part[name] for part in parts]).reshape(unixtime.shape)
        for name in parts[0]
    }


def _geocentric(unixtime: np.ndarray, delta_t: float) -> dict:
    """:func:`spa_geocentric` at instants ``unixtime`` [s], at once."""
    import pvlib

    spa = pvlib.spa
    jd = spa.julian_day(unixtime)
    jde = spa.julian_ephemeris_day(jd, delta_t)
    jc = spa.julian_century(jd)
    jce = spa.julian_ephemeris_century(jde)
    jme = spa.julian_ephemeris_millennium(jce)
    args = (
        spa.mean_elongation(jce),
        spa.mean_anomaly_sun(jce),
        spa.mean_anomaly_moon(jce),
        spa.moon_argument_latitude(jce),
        spa.moon_ascending_longitude(jce),
    )
    sums, (delta_psi, delta_epsilon) = _periodic(spa, jme, jce, args)
    radius = _heliocentric(sums["R"], jme)
    theta = spa.geocentric_longitude(np.rad2deg(_heliocentric(sums["L"], jme)) % 360)
    beta = spa.geocentric_latitude(np.rad2deg(_heliocentric(sums["B"], jme)))
    epsilon = spa.true_ecliptic_obliquity(spa.mean_ecliptic_obliquity(jme), delta_epsilon)
    lamd = spa.apparent_sun_longitude(theta, delta_psi, spa.aberration_correction(radius))
    v = spa.apparent_sidereal_time(spa.mean_sidereal_time(jd, jc), delta_psi, epsilon)
    alpha = spa.geocentric_sun_right_ascension(lamd, epsilon, beta)
    delta = spa.geocentric_sun_declination(lamd, epsilon, beta)
    eot = spa.equation_of_time(spa.sun_mean_longitude(jme), alpha, delta_psi, epsilon)
    return {
        "alpha": alpha,
        "delta": delta,
        "v": v,
        "xi": spa.equatorial_horizontal_parallax(radius),
        "eot": eot,
    }


_SERIES = ("L", "B", "R")  # the Earth's heliocentric longitude, latitude and radius


@functools.cache
def _periodic_tables(spa) -> tuple:
    """``pvlib.spa``'s tables of the heliocentric series' periodic terms (Table A4.2: ``L0``,
    ``L1``..., ``B0``..., ``R0``... of ``spa``, the module ``pvlib.spa``) one after the other, (n,
    3), the bounds of each table's rows, and the tables of each series, as
    :func:`foldopt.physics.spa_site.periodic_sums` reads them: constants, gathered once a
    process (writable, as the compiled pass's one specialisation takes them: never written)."""
    tables = {
        series: [getattr(spa, f"{series}{k}") for k in range(6) if hasattr(spa, f"{series}{k}")]
        for series in _SERIES
    }
    rows = [table for series in _SERIES for table in tables[series]]
    bounds = np.cumsum([0] + [table.shape[0] for table in rows])
    counts = [len(tables[series]) for series in _SERIES]
    return np.ascontiguousarray(np.concatenate(rows), dtype=float), bounds, counts


def _periodic(spa, jme, jce, args) -> tuple:
    """SPA's periodic series [1]_ at every instant: each table's sum of the Earth's heliocentric
    terms (Eq. 9-10: ``sum A cos(B + C jme)``), ``{'L': [L0, L1...], 'B': [...], 'R': [...]}``,
    and the nutation in longitude and obliquity [deg] (Eq. 15-22). One compiled pass over the
    instants on numba's threads (:func:`foldopt.physics.spa_site.periodic_sums`): each element by
    the operations of ``pvlib.spa``'s loops over the terms in their order, so its bits
    (tests/test_solarposition.py; pvlib's ``sum_mult_cos_add_mult`` costs a NumPy call a term).

    Parameters
    ----------
    spa : module
        ``pvlib.spa``.
    jme, jce : numpy.ndarray
        The Julian ephemeris millennium and century of each instant, 1-D.
    args : tuple of numpy.ndarray
        The nutation's five arguments ``X0`` to ``X4`` [deg] (Eq. 15-19).
    """
    from foldopt.physics.spa_site import periodic_sums  # numba's compiled pass

    terms, bounds, counts = _periodic_tables(spa)
    jme, jce = np.ascontiguousarray(jme, dtype=float), np.ascontiguousarray(jce, dtype=float)
    x = np.ascontiguousarray(np.stack(np.broadcast_arrays(*args)), dtype=float)
    abcd = np.ascontiguousarray(spa.NUTATION_ABCD_ARRAY, dtype=float)
    y = np.ascontiguousarray(spa.NUTATION_YTERM_ARRAY, dtype=float)
    sums, nutation = np.empty((len(bounds) - 1, jme.size)), np.empty((2, jme.size))
    _on_threads(
        lambda part: periodic_sums(
            terms, bounds, jme, abcd, y, jce, x, sums, nutation, part.start, part.stop
        ),
        jme.size,
        jme.size,
        PERIODIC_INSTANTS_A_THREAD,
    )
    tables = np.split(sums, np.cumsum(counts)[:-1])
    return dict(zip(_SERIES, tables, strict=True)), (
        nutation[0] * 1.0 / 36000000,
        nutation[1] * 1.0 / 36000000,
    )


def _heliocentric(sums, jme):
    """``pvlib.spa``'s heliocentric longitude, latitude or radius [1]_ (Eq. 9-11, before its
    conversion to degrees) from its tables' sums (:func:`_periodic`), the polynomial in ``jme`` as
    pvlib writes it, so its bits (tests/test_solarposition.py)."""
    total = sums[0]
    for k in range(1, len(sums)):
        total = total + sums[k] * jme**k
    return total / 10**8


_WRAPPED = ("alpha", "v")  # angles that wrap at 360 deg
_GEOCENTRIC = ("alpha", "delta", "v", "xi", "eot")  # the terms the sun takes, in their order


class SunTerms:
    """SPA's time-only terms at the instants one run has asked for, so that its sites and chunks
    share them: at whole UTC hours (:meth:`at_hours`) and at the steps of each UTC lattice
    (:meth:`on_lattice`). The terms are elementwise in time, so an instant's are the same bits
    whichever call first asked for it (tested); a run that passes none evaluates its own.

    The owner is the run: a sweep over a year's chunks, a map's chunk of sites. Each store is
    replaced whole (one assignment), so that threads of one run read one state or the other.

    Attributes
    ----------
    hours_kept, steps_kept : int
        Bounds of each store (about 80 MB and 60 MB at the defaults): past them a store starts
        again, or a lattice is not kept.
    """

    def __init__(self, hours_kept: int = 2_000_000, steps_kept: int = 1_500_000):
        self.hours_kept, self.steps_kept = hours_kept, steps_kept
        self._hours: tuple = (np.zeros(0, dtype=np.int64), {})
        self._lattices: dict = {}

    def at_hours(self, nodes: np.ndarray) -> dict:
        """:func:`spa_geocentric` at whole UTC hours ``nodes`` (sorted, unique), each evaluated
        once for the run."""
        hours, terms = self._hours
        missing = nodes[~np.isin(nodes, hours)]
        if missing.size:
            found = spa_geocentric(missing * 3600.0)
            if hours.size + missing.size > self.hours_kept:
                hours, terms = missing[:0], {name: values[:0] for name, values in found.items()}
            order = np.argsort(np.concatenate([hours, missing]), kind="stable")
            hours = np.concatenate([hours, missing])[order]
            terms = {
                name: np.concatenate([terms.get(name, values[:0]), values])[order]
                for name, values in found.items()
            }
            self._hours = (hours, terms)
        index = np.searchsorted(hours, nodes)
        return {name: values[index] for name, values in terms.items()}

    def on_lattice(self, utc_ns: np.ndarray) -> tuple:
        """:func:`_equatorial` at ``utc_ns`` (n_blocks, n_steps) as ``(first, terms)``: block
        ``b``'s step ``i`` is ``terms[:, first[b] + i]``. Where every day is of equal steps on one
        lattice of UTC instants (a map's sites of one year and step, whatever their time zone),
        each instant is evaluated once for the run however many sites and days share it, and only
        the instants the days span: a sweep's days spread over a year evaluate those days alone."""
        n_blocks, n_steps = utc_ns.shape
        step, phase = _lattice(utc_ns)
        if not step:
            return np.arange(n_blocks) * n_steps, _equatorial(utc_ns, self).reshape(5, -1)
        start = (utc_ns[:, 0] - phase) // step
        low, high = int(start.min()), int(start.max()) + n_steps - 1
        first, terms, known = self._lattices.get(
            (step, phase), (low, np.zeros((5, 0)), np.zeros(0, dtype=bool))
        )
        size = terms.shape[1]
        grown = low < first or high >= first + size
        if grown:
            # A day more either side: the same dates in every other time zone then fit.
            margin = -(-24 * NS_PER_HOUR // step)
            low, high = min(low - margin, first), max(high + margin, first + size - 1)
            if high - low + 1 > self.steps_kept:
                return np.arange(n_blocks) * n_steps, _equatorial(utc_ns, self).reshape(5, -1)
            kept = slice(first - low, first - low + size)
            old_terms, old_known = terms, known
            terms, known = np.zeros((5, high - low + 1)), np.zeros(high - low + 1, dtype=bool)
            terms[:, kept], known[kept] = old_terms, old_known
            first = low
        # The instants the blocks span that no call has evaluated yet.
        spanned = _spanned(start - first, n_steps, terms.shape[1])
        missing = spanned[~known[spanned]]
        if missing.size:
            if not grown:  # the run's other calls may hold the store: a copy is filled
                terms, known = terms.copy(), known.copy()
            terms[:, missing] = _equatorial((missing + first) * step + phase, self)
            known[missing] = True
            self._lattices = {**self._lattices, (step, phase): (first, terms, known)}
        return start - first, terms


def _lattice(utc_ns) -> tuple[int, int]:
    """``(step, phase)`` [ns] of the UTC lattice on which every block of ``utc_ns`` (n_blocks,
    n_steps) lies, its days of equal steps; ``(0, 0)`` where none does (a clock's change, a DST
    day, breaks a day's steps)."""
    n_steps = utc_ns.shape[1]
    step = int(utc_ns[0, 1] - utc_ns[0, 0]) if n_steps > 1 else 0
    phase = int(utc_ns[0, 0] % step) if step > 0 else 0
    on_it = (
        step > 0
        and np.all(utc_ns[:, 0] % step == phase)
        and np.all(utc_ns[:, -1] - utc_ns[:, 0] == step * (n_steps - 1))
    )
    return (step, phase) if on_it else (0, 0)


def equatorial_once(utc_ns) -> tuple:
    """:meth:`SunTerms.on_lattice` for a call that shares its terms with no other (a sky built
    alone): the instants its blocks span, each once, in a store of those instants alone, not of
    the lattice from the first to the last (a year's for days spread over it).

    Parameters
    ----------
    utc_ns : numpy.ndarray of int64
        (n_blocks, n_steps) UTC instants [ns].

    Returns
    -------
    first, terms : numpy.ndarray
        As :meth:`SunTerms.on_lattice`'s: block ``b``'s step ``i`` is ``terms[:, first[b] + i]``.
    """
    n_blocks, n_steps = utc_ns.shape
    step, phase = _lattice(utc_ns)
    if not step:
        return np.arange(n_blocks) * n_steps, _equatorial(utc_ns, SunTerms()).reshape(5, -1)
    start = (utc_ns[:, 0] - phase) // step
    low = int(start.min())
    spanned = _spanned(start - low, n_steps, int(start.max()) - low + n_steps)
    # A block's instants are consecutive on the lattice, so they are consecutive among the
    # spanned ones too.
    return np.searchsorted(spanned, start - low), _equatorial(
        (spanned + low) * step + phase, SunTerms()
    )


def _spanned(starts, n_steps: int, size: int) -> np.ndarray:
    """The sorted instants of a lattice of ``size`` that blocks of ``n_steps`` beginning at
    ``starts`` span: each block's own where no two overlap (days apart, as a run's days in one time
    zone are), else where the blocks begin and end, summed along the lattice (a pass over the
    whole lattice, which costs a short run more than its days)."""
    begins = np.unique(starts)
    if begins.size < 2 or np.diff(begins).min() >= n_steps:
        return (begins[:, None] + np.arange(n_steps)).ravel()
    edges = np.zeros(size + 1, dtype=np.int64)
    np.add.at(edges, starts, 1)
    np.add.at(edges, starts + n_steps, -1)
    return np.flatnonzero(np.cumsum(edges[:-1]) > 0)


def _geocentric_hourly(utc_ns: np.ndarray, sun_terms: SunTerms) -> tuple:
    """:func:`spa_geocentric` at the whole UTC hours that ``utc_ns`` (any shape) touch, each hour
    evaluated once however many sites and days share it (:meth:`SunTerms.at_hours`), to be
    interpolated linearly between them (:func:`foldopt.physics.spa_site.equatorial_steps`).

    Over an hour the geocentric terms are smooth to within 1e-5 deg of linear (tested).

    Returns
    -------
    at_nodes : numpy.ndarray
        (5, n_nodes) the terms ``alpha``, ``delta``, ``v``, ``xi`` and ``eot`` at the hours.
    change : numpy.ndarray
        (5, n_nodes - 1) each hour's change to the next (``alpha`` and ``v`` wrapped to
        [-180, 180) deg), worked out once an hour rather than once a step.
    index : numpy.ndarray of int64
        The hour of each instant among the nodes, ``utc_ns`` flattened.
    """
    hours = np.floor_divide(utc_ns, NS_PER_HOUR)
    nodes, index = _hour_nodes(hours)
    at_nodes = sun_terms.at_hours(nodes)
    values = np.stack([at_nodes[name] for name in _GEOCENTRIC])
    # An hour's next node is always its own next hour.
    change = values[:, 1:] - values[:, :-1]
    for row, name in enumerate(_GEOCENTRIC):
        if name in _WRAPPED:
            change[row] = (change[row] + 180.0) % 360.0 - 180.0
    return values, change, np.ascontiguousarray(index.ravel())


def _hour_nodes(hours: np.ndarray) -> tuple:
    """The sorted whole hours that ``hours`` (any shape) and the hours after them touch, and where
    each of ``hours`` is among them: ``np.unique`` of both and ``np.searchsorted``, by marks on
    the range of hours (a year of 1-min steps has half a million instants but 9,000 hours)."""
    flat = hours.ravel()
    low = int(flat.min()) if flat.size else 0
    width = int(flat.max()) - low + 2 if flat.size else 0
    if width > 8 * flat.size + 1_000_000:  # instants spread over centuries: sorting is cheaper
        nodes = np.unique(np.concatenate([flat, flat + 1]))
        return nodes, np.searchsorted(nodes, hours)
    marks = flat - low
    touched = np.zeros(width, dtype=bool)
    touched[marks] = True
    # each hour's next one: a pass over the range rather than a second scatter of the instants
    touched[1:] |= touched[:-1].copy()
    nodes = np.flatnonzero(touched) + low
    return nodes, (np.cumsum(touched) - 1)[marks].reshape(hours.shape)


def _equatorial(utc_ns, sun_terms: SunTerms) -> np.ndarray:
    """The time-only terms of a site's sun at UTC instants ``utc_ns`` (any shape), from SPA's
    geocentric terms interpolated between whole UTC hours (:func:`_geocentric_hourly`): the sun's
    direction in the frame of the Greenwich meridian and the celestial pole, ``cos(delta)
    cos(H_G)``, ``cos(delta) sin(H_G)`` and ``sin(delta)`` with ``H_G = v - alpha`` its Greenwich
    hour angle [1]_ (Eq. 34 at longitude 0); ``sin(xi)``, the scale of the parallax; and the
    equation of time [min]. (5, ...). Every step in one compiled pass on numba's threads
    (:func:`foldopt.physics.spa_site.equatorial_steps`, which says why its bits are NumPy's)."""
    from foldopt.physics.spa_site import equatorial_steps  # numba's compiled pass

    utc_ns = np.asarray(utc_ns)
    at_nodes, change, index = _geocentric_hourly(utc_ns, sun_terms)
    flat = np.ascontiguousarray(utc_ns.ravel())
    out = np.empty((5, flat.size))
    _on_threads(
        lambda part: equatorial_steps(flat, index, at_nodes, change, out, part.start, part.stop),
        flat.size,
        flat.size,
        EQUATORIAL_STEPS_A_THREAD,
    )
    return out.reshape((5, *utc_ns.shape))


#: The work of a thread of the compiled passes below which it is not worth its start (some 0.05
#: to 0.1 ms; each pass 0.2-0.3 ms of work): blocks x steps of the per-site pass (some 50 ns a
#: step), instants of the equatorial terms (some 65 ns) and of SPA's periodic series (4 us).
SITE_STEPS_A_THREAD = 5_000
EQUATORIAL_STEPS_A_THREAD = 4_000
PERIODIC_INSTANTS_A_THREAD = 60


def _on_threads(run, n: int, steps: int, least: int) -> None:
    """``run(part)`` over slices ``part`` of ``range(n)`` (of ``steps`` steps in all), on numba's
    threads, each thread ``least`` steps or more: the compiled passes release the GIL, and their
    items (blocks, instants) are independent. The last part runs in the calling thread."""
    from numba import get_num_threads

    threads = min(get_num_threads(), n, max(1, steps // least))
    parts = [slice(n * k // threads, n * (k + 1) // threads) for k in range(threads)]
    if threads == 1:
        run(parts[0])
        return
    others = submit(threads - 1, [functools.partial(run, part) for part in parts[:-1]])
    run(parts[-1])
    for done in others:
        done.result()  # a part's error, raised here


def spa_solar_position(utc_ns, latitude, longitude, altitude, sun_terms: SunTerms | None = None):
    """Apparent zenith, azimuth, hour angle and the sun's apparent unit vector by SPA [1]_ at every
    step of days of steps.

    SPA's geocentric terms depend on time alone: kept per UTC hour and interpolated
    (:func:`_geocentric_hourly`), they give the sun's direction in the frame of the Greenwich
    meridian and the celestial pole (:func:`_equatorial`), the same for every site at an instant
    and kept per step (:meth:`SunTerms.on_lattice`). A site's topocentric direction is that vector turned
    by the site's longitude and latitude, less the site's own position seen from the Earth's centre
    (``x`` and ``y`` of [1]_ Eq. 38-39, scaled by ``sin(xi)``): the vector form of SPA's parallax in
    right ascension and declination (Eq. 40-41, 43-45), exact, with no trigonometry per step but
    the elevation's and the azimuth's. SPA's refraction correction (Eq. 42, pvlib's formula, with
    pvlib's default pressure for the altitude and 12 C) raises it at every step; all of it one
    compiled pass over the steps (:func:`foldopt.physics.spa_site.site_sun`). Against pvlib's
    ``spa_python`` on random sites and days at 1-min steps, the sun's direction is within 2e-6 deg
    (tests/test_solarposition.py).

    Parameters
    ----------
    utc_ns : numpy.ndarray of int64
        (n_blocks, n_steps) UTC instants [ns since 1970-01-01]
        (:attr:`foldopt.physics.solarposition.ClockGrid.utc_ns`).
    latitude, longitude : float or array_like
        [deg north], [deg east]; one value, or one per block, shape (n_blocks, 1).
    altitude : float or array_like
        [m], as ``latitude``.
    sun_terms : SunTerms, optional
        The run's time-only terms, shared with its other calls; default: this call's own.

    Returns
    -------
    apparent_zenith, solar_azimuth : numpy.ndarray
        [deg], azimuth clockwise from north, (n_blocks, n_steps).
    hour_angle : numpy.ndarray
        [deg] in [-180, 180), (n_blocks, n_steps): pvlib's formula ``15 (UTC hours - 12) +
        longitude + EoT / 4`` with SPA's equation of time (EoT, [min]), worked out from UTC (so DST
        days need no care).
    sun_vector : numpy.ndarray
        (n_blocks, n_steps, 3) the apparent direction's east, north and up components [-] (a view of
        an array laid out (n_blocks, 3, n_steps), each component contiguous along the steps).

    References
    ----------
    .. [1] I. Reda, A. Andreas, "Solar position algorithm for solar radiation applications",
       Solar Energy 76(5), 577-589, 2004, Sec. 3.10-3.14 and A.1.
    """
    utc_ns = np.ascontiguousarray(utc_ns, dtype=np.int64)
    shape = utc_ns.shape

    def per_block(values):
        # a copy: one type (writable, contiguous) for the compiled pass whatever the caller's
        return np.array(np.broadcast_to(np.asarray(values, dtype=float), (shape[0], 1))[:, 0])

    latitude, longitude, altitude = per_block(latitude), per_block(longitude), per_block(altitude)
    import pvlib

    u = pvlib.spa.uterm(latitude)
    x, y = pvlib.spa.xterm(u, latitude, altitude), pvlib.spa.yterm(u, latitude, altitude)
    lam, phi = np.radians(longitude), np.radians(latitude)
    first, terms = equatorial_once(utc_ns) if sun_terms is None else sun_terms.on_lattice(utc_ns)
    # each component along the steps, as the engine reads it
    vector = np.empty((shape[0], 3, shape[1]))
    apparent_zenith, solar_azimuth, hour_angle = np.empty(shape), np.empty(shape), np.empty(shape)
    pressure = np.ascontiguousarray(pvlib.atmosphere.alt2pres(altitude) / 100.0)
    per_site = (utc_ns, first, longitude, np.sin(lam), np.cos(lam), np.sin(phi), np.cos(phi))
    per_site += (x, y, pressure)
    outputs = (vector, apparent_zenith, solar_azimuth, hour_angle)
    from foldopt.physics.spa_site import site_sun  # numba's compiled pass

    _on_threads(
        lambda part: site_sun(terms, *(a[part] for a in per_site + outputs)),
        shape[0],
        shape[0] * shape[1],
        SITE_STEPS_A_THREAD,
    )
    return apparent_zenith, solar_azimuth, hour_angle, np.moveaxis(vector, 1, -1)
