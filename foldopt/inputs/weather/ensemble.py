"""Cloud ensembles: members of minute light drawn from a weather file's hourly means, each member a
different passage of clouds over the same hours.

A storage-less load stops whenever a cloud hides the sun, so an hour's mean says too little: a
broken-cloud hour and a thin-overcast hour of the same mean stop a load very differently, and the
mean cannot tell them apart. Each member therefore draws, hour by hour, which of the two the hour
was: overcast (the sun never distinct: smooth light at the hour's level) or broken, the two-state
sky of Morf [2]_ and Bright et al. [1]_ (at every instant the sun visible or obscured; the beam the
hour's while visible, none while obscured; the diffuse the hour's, smooth, in both). Every hour of
every member keeps the file's mean GHI and DHI exactly.

The model, step by step (:func:`cloud_members`):

1. The hour's sunshine fraction ``s``: one minus the file's total sky cover where it gives one
   (the sun obscured for the part of the hour the sky is covered [1]_); else from the hour's
   clear-sky index ``k`` by Suehrcke, Bowden & Hollands' relation [4]_ inverted,

   (1) ``k = beta + (1 - beta) s**gamma``, ``beta = 0.1898``, ``gamma = 0.7410``;

   then bounded by the hour's beam ``B = ghi - dhi``: at most ``B / (120 cos(zenith))`` (sunshine
   is a DNI of at least 120 W/m^2 [5]_), at least what the bound on over-irradiance needs.
2. Overcast or broken: the hour's chance of 8 oktas given its index and solar elevation ``h``
   (the nearest 10 deg bin up to 50 deg), by Bayes from Smith, Bright & Crook's fitted densities
   of the hourly clear-sky index in each cover [6]_, Burr type III for 0-3 oktas and generalised
   gamma for 4-8,

   (2) ``f_N(x) = (c k / a) (x / a)**(-c - 1) (1 + (x / a)**-c)**(-k - 1)``,
   (3) ``f_N(x) = p x**(d - 1) exp(-(x / a)**p) / (a**d Gamma(d / p))``,
   (4) ``P(overcast | k, h) = f_8(k; h) / sum over N = 0..8 of f_N(k; h)``,

   the oktas taken as equally likely beforehand (an assumption: a file says nothing of the site's
   cloud climate; Smith et al.'s fits are UK hours). Where the file gives a cover, the hour is
   overcast when the cover is full. An hour of full sunshine (``s = 1``) is never overcast (the
   fits' tails above ``k = 1`` say nothing of cloud). Overcast spells persist: each member carries
   a uniform variate ``u`` from one lit hour to the next with Bright et al.'s hourly persistence of
   8 oktas [1]_, ``rho = 0.85``, redrawing it otherwise (and after a dark hour), and

   (5) the hour is overcast when ``u < P(overcast | k, h)``,

   so that each hour is overcast with its own chance (4) and neighbouring hours tend to agree.
3. Which steps of a broken hour are sunny: a continuous-time two-state Markov chain [2]_ run
   through the lit hours in order (its state carried from hour to hour; after a dark hour it starts
   afresh), sunny with probability ``s``, its runs of the mean length of Bright et al.'s cloud and
   gap chords: their power law ``p(x) ~ x**-1.66`` from 100 m to 1500 km after Wood & Field [3]_
   (mean 4.9 km), passing at their cloud speed, ``Gamma(2.7, 2.144)`` m/s within 1 to 60 m/s,
   drawn every hour [1]_ (about 14 min at the mean speed when ``s = 1/2``). Each hour's runs are
   then stretched or shrunk, in order and keeping its first and last states, so that the sun
   shines exactly ``s`` of it (Bright et al. keep only sampled hours of the hour's cover [1]_). An
   overcast hour, or one in which the chain does not switch (slow clouds), takes its beam evenly,
   as a hazy sun.
4. The light: the diffuse is the hour's clear-sky diffuse index, linear between hour centres (held
   beyond the first and last), times the clear sky; the beam of a sunny step is the hour's sunny
   DNI ``B / (s cos(zenith))``, linear alike, times ``cos(zenith)`` (a clear DNI varies little
   within an hour, and a clear-sky model's error at a low sun, where it may be far too dark, does
   not shape it). Both take Bright et al.'s white noise of relative standard deviation

   (6) ``0.001 + 0.0015 N`` while the sun is visible, ``0.01 + 0.003 N`` while obscured,

   their eqs. (12) and (13) [1]_, ``N`` the cover in oktas (``8 (1 - s)`` where the file gives
   none, 8 in an overcast hour). Each hour's diffuse and beam are then scaled to the file's means;
   the GHI is their sum, at most :data:`MAX_ENHANCEMENT` times the clear sky, or that times the
   hour's own index where it is above 1 (a clear sky the model underrates), and never above
   :data:`~foldopt.inputs.weather.downscale.MAX_CLEARSKY_INDEX` times it; the DNI is
   ``beam / cos(zenith)``.

Left out of Bright et al.'s model [1]_: its Markov chains of hourly cover, wind, cloud height and
pressure (the hours here are the file's; only the overcast persistence is kept); its cloud speed
from wind and cloud height (here its distribution above 1 km); its strict alternation of power-law
chords (here a chain of their mean run length; sub-minute chords average away in a minute); its
clear-sky index distributions for obscured minutes (here the levels follow from the hour's GHI and
DHI); its smoothing of long spells, cloud-edge peaks and beam relation. Suehrcke et al. derive (1)
for days and months [4]_; it is used here for hours. The chain runs on steps of at most
:data:`CHAIN_STEP_MIN`; a coarser study step averages its sub-steps, a finer one keeps its own.

Checked, not fitted, against measured minute days (foldopt.studies.validation): clear days stay
deterministic and within about 0.1 h of the smooth path's t_solar at most loads; on broken days
the members' P5-P95 holds the measured t_solar at most low and middle loads. Thin, variable
overcast that (4) gives a small chance (MIDC BMS 2018-10-14, hours 10-12, ``k`` 0.6-0.7: 5-10 %)
is still drawn broken by most members, whose t_solar at high loads then falls short.

References
----------
.. [1] J. M. Bright, C. J. Smith, P. G. Taylor, R. Crook, "Stochastic generation of synthetic
   minutely irradiance time series derived from mean hourly weather observation data", Solar
   Energy 115, 229-242, 2015; the parameters as in the authors' code (BrightSolarModel, GitHub
   JamieMBright): chord law, cloud speed (after Mathiesen et al., Solar Energy 92, 47-61, 2013),
   noise of eqs. (12)-(13), and the hourly cloud-cover transitions (supportingfiles
   cum_winterhp_prob.txt and cum_winterlp_prob.txt: 8 oktas to 8 oktas 0.849 and 0.859).
.. [2] H. Morf, "The stochastic two-state solar irradiance model (STSIM)", Solar Energy 62(2),
   101-112, 1998: the sun covered or not, the state switching as a Markov process.
.. [3] R. Wood, P. R. Field, "The distribution of cloud horizontal sizes", Journal of Climate
   24(18), 4800-4816, 2011: a single power law of exponent 1.66 from 0.1 to 1500 km.
.. [4] H. Suehrcke, R. S. Bowden, K. G. T. Hollands, "Relationship between sunshine duration and
   solar radiation", Solar Energy 92, 160-171, 2013: the clear-sky-normalised clearness index
   against the sunshine fraction, ``beta + (1 - beta) s**gamma``.
.. [5] WMO, "Guide to Meteorological Instruments and Methods of Observation" (WMO-No. 8), chapter
   on sunshine duration: the sun shines while the direct normal irradiance is at least 120 W/m^2.
.. [6] C. J. Smith, J. M. Bright, R. Crook, "Cloud cover effect of clear-sky index distributions
   and differences between human and automatic cloud observations", Solar Energy 144, 10-21,
   2017: hourly clear-sky index at 63 UK stations 2010-2013 by okta and solar elevation, Burr III
   (0-3 oktas) and generalised gamma (4-8) fits; the coefficients of automatic observations as
   in Bright et al.'s code [1]_ (clear-sky-distribution-coefficients.txt).
"""

from __future__ import annotations

import math

import numpy as np

from foldopt.inputs.weather.downscale import (
    MAX_CLEARSKY_INDEX,
    MIN_COS_ZENITH,
    fill_dark,
    interpolate_points,
)

#: Suehrcke, Bowden & Hollands' global relation [4]_: clear-sky index ``beta + (1 - beta) s**gamma``
#: of an hour in sunshine for the fraction ``s`` of it.
SUNSHINE_BETA = 0.1898
SUNSHINE_GAMMA = 0.7410
#: WMO's threshold of sunshine [5]_: the sun shines while the DNI is at least this [W/m^2].
SUNSHINE_DNI = 120.0
#: Bright et al.'s cloud and gap chords [1]_ after Wood & Field [3]_: ``p(x) ~ x**-1.66`` between
#: the two lengths [m].
CHORD_EXPONENT = 1.66
CHORD_RANGE = (100.0, 1.5e6)
#: Bright et al.'s cloud speed [1]_ (cloud base above 1 km): Gamma of this shape and scale [m/s],
#: within this range [m/s], drawn every hour.
SPEED_SHAPE, SPEED_SCALE = 2.7, 2.144
SPEED_RANGE = (1.0, 60.0)
#: Bright et al.'s eqs. (12)-(13) [1]_: relative standard deviation ``a + b N`` (``N`` the cover in
#: oktas) of a step's white noise while the sun is visible, and while it is obscured.
NOISE_VISIBLE = (0.001, 0.0015)
NOISE_OBSCURED = (0.01, 0.003)
#: Bound of the clear-sky index of a step (cloud enhancement), unless its hour's own index is higher.
MAX_ENHANCEMENT = 1.5
#: Longest step of the two-state chain [min]; a coarser study step averages sub-steps of this.
CHAIN_STEP_MIN = 1.0
#: Smith, Bright & Crook's fits of the hourly clear-sky index in each cloud cover [6]_ (their
#: automatic observations, as in Bright et al.'s code [1]_): rows 0 to 8 oktas, columns the solar
#: elevation bins 0, 10, ..., 50 deg, each ``(scale, shape1, shape2)``; 0-3 oktas Burr type III,
#: 4-8 oktas generalised gamma (eqs. (2)-(3) of the module docstring). The two bins they leave empty
#: (0 oktas at 30 deg, 8 oktas at 20 deg) take the mean of their neighbours' parameters.
COVER_FITS = np.array(
    [
        [
            (1.00426, 8.05209, 0.33413),
            (1.05008, 30.0122, 0.15747),
            (1.04270, 79.3070, 0.10978),
            (np.nan,) * 3,
            (1.04161, 90.4486, 0.11474),
            (1.04035, 106.678, 0.11517),
        ],
        [
            (0.86772, 5.95703, 0.46153),
            (1.03464, 23.3098, 0.13596),
            (1.05403, 45.7765, 0.08633),
            (1.05343, 61.2289, 0.07964),
            (1.04837, 68.6886, 0.08091),
            (1.05109, 83.3814, 0.07648),
        ],
        [
            (0.77206, 4.95605, 0.60222),
            (0.99764, 16.1237, 0.17120),
            (1.04272, 33.0440, 0.09915),
            (1.04420, 43.3609, 0.08753),
            (1.03914, 44.6569, 0.09412),
            (1.04245, 59.1349, 0.08163),
        ],
        [
            (0.75709, 4.71996, 0.59981),
            (0.96289, 13.2643, 0.20049),
            (1.02061, 24.5572, 0.12518),
            (1.02210, 29.5048, 0.11747),
            (1.01606, 35.5753, 0.10865),
            (1.01776, 40.2873, 0.10703),
        ],
        [
            (0.00548, 0.55740, 7.91970),
            (0.80680, 3.78063, 3.21570),
            (0.97459, 7.68441, 3.13980),
            (0.99304, 10.0262, 3.49195),
            (0.99518, 11.9358, 3.63087),
            (0.99403, 14.3796, 4.15190),
        ],
        [
            (0.00202, 0.49130, 8.15754),
            (0.66456, 2.79245, 3.43021),
            (0.89225, 5.43828, 3.23124),
            (0.94539, 7.63587, 3.31306),
            (0.93125, 8.26040, 3.65375),
            (0.93577, 9.66092, 3.88766),
        ],
        [
            (0.00168, 0.48199, 8.08929),
            (0.48615, 2.08814, 3.83716),
            (0.75785, 3.82376, 3.33406),
            (0.85162, 5.45712, 3.18022),
            (0.85237, 5.90425, 3.43888),
            (0.84646, 6.32450, 3.81557),
        ],
        [
            (0.00454, 0.48462, 4.42115),
            (0.43349, 1.79971, 2.24003),
            (0.61461, 2.62790, 2.02528),
            (0.70374, 3.46998, 2.06773),
            (0.73038, 4.01204, 2.19332),
            (0.74453, 4.48931, 2.18655),
        ],
        [
            (0.00017, 0.36012, 5.35531),
            (0.09720, 1.01097, 3.44283),
            (np.nan,) * 3,
            (0.20153, 1.33134, 2.95643),
            (0.26613, 1.55354, 2.83336),
            (0.25640, 1.54127, 2.89782),
        ],
    ]
)
COVER_FITS[0, 3] = COVER_FITS[0, [2, 4]].mean(axis=0)
COVER_FITS[8, 2] = COVER_FITS[8, [1, 3]].mean(axis=0)
#: Bright et al.'s hourly Markov chain of cloud cover [1]_: an overcast (8 okta) hour is followed
#: by another with probability 0.85 (their winter transition tables: 0.849 and 0.859).
OVERCAST_PERSISTENCE = 0.85


def _mean_chord(exponent=CHORD_EXPONENT, lengths=CHORD_RANGE):
    """Mean of the power law ``p(x) ~ x**-exponent`` between two lengths [m]."""
    a, b = lengths
    return (
        (1 - exponent)
        / (2 - exponent)
        * (b ** (2 - exponent) - a ** (2 - exponent))
        / (b ** (1 - exponent) - a ** (1 - exponent))
    )


#: Mean length of Bright et al.'s chords [m] (4.9 km): one mean run of the chain when ``s = 1/2``.
MEAN_CHORD = _mean_chord()


def _sunshine(index):
    """Sunshine fraction of an hour of clear-sky index ``index``, Suehrcke et al.'s relation
    inverted [4]_: 0 up to ``beta``, 1 from the clear sky up."""
    base = np.clip((np.asarray(index, dtype=float) - SUNSHINE_BETA) / (1 - SUNSHINE_BETA), 0.0, 1.0)
    return base ** (1 / SUNSHINE_GAMMA)


def _overcast(index, elevation):
    """Probability that an hour of clear-sky index ``index`` and solar elevation ``elevation`` [deg]
    is overcast (8 oktas), eq. (4) of the module docstring: Smith et al.'s densities [6]_, the
    oktas equally likely beforehand."""
    x = np.clip(np.asarray(index, dtype=float), 1e-3, None)[None]
    scale, c, k = np.moveaxis(
        COVER_FITS[:, np.clip(np.rint(elevation / 10.0), 0, 5).astype(int)], -1, 0
    )
    log_x = np.log(x / scale)
    burr = np.log(c * k / scale) - (c + 1) * log_x - (k + 1) * np.logaddexp(0.0, -c * log_x)
    gamma_fn = np.vectorize(math.lgamma)(k / c)
    with np.errstate(over="ignore"):  # far in a density's tail: its log -inf, its limit (zero)
        gen = np.log(c / scale) + (k - 1) * log_x - np.exp(c * log_x) - gamma_fn
    log_f = np.where(np.arange(9).reshape(-1, *([1] * x.ndim)[1:]) < 4, burr, gen)
    return np.exp(log_f[8] - np.logaddexp.reduce(log_f, axis=0))


def _overcast_hours(chance, fresh, rngs):
    """(members, n) which of ``n`` lit intervals in order each member draws overcast, eq. (5) of the
    module docstring: a uniform variate per member kept from one interval to the next with the
    probability :data:`OVERCAST_PERSISTENCE`, else (and where ``fresh``, after a dark one) redrawn,
    below each interval's ``chance``."""
    n = chance.size
    keep = np.stack([rng.random(n) for rng in rngs]) < OVERCAST_PERSISTENCE
    keep[:, fresh] = False
    level = np.stack([rng.random(n) for rng in rngs])
    redrawn = np.maximum.accumulate(np.where(keep, 0, np.arange(n)), axis=1)
    return np.take_along_axis(level, redrawn, axis=1) < chance


def _envelope(index, valid, clear, spi: int):
    """(n_days, n_intervals, spi): an interval index linear between interval centres, held beyond
    the first and the last; an invalid interval takes its day's nearest valid one (0 for a day
    with none); times the clear sky."""
    curve = interpolate_points(fill_dark(index, valid), 0.0, spi)
    return curve.reshape(index.shape + (spi,)) * clear


def _fill(values, cap, means, rounds: int = 16):
    """``values`` (..., n_intervals, spi) >= 0 scaled by one factor per interval, at most ``cap``,
    so that each interval's mean is ``means`` (water-filling: the steps the cap holds keep it, the
    others take the rest); where the cap cannot hold the mean, the interval is at its cap."""
    cap = np.maximum(cap, 0.0)
    free = values.sum(axis=-1)
    total = np.broadcast_to(means * values.shape[-1], free.shape)
    factor = np.divide(total, free, out=np.zeros_like(free), where=free > 0)
    out = factor[..., None] * values
    rows = (out > cap).any(axis=-1)
    if rows.any():  # the few intervals the cap cuts: iterate on those alone
        v, c, t, f = (
            values[rows],
            np.broadcast_to(cap, values.shape)[rows],
            total[rows],
            factor[rows],
        )
        full = np.zeros(t.shape, dtype=bool)  # every step at its cap
        for _ in range(rounds):
            capped = f[:, None] * v > c
            rest = np.where(capped, 0.0, v).sum(axis=-1)
            need = t - np.where(capped, c, 0.0).sum(axis=-1)
            full = rest <= 0
            update = np.where(full, f, np.divide(need, rest, out=np.zeros_like(need), where=~full))
            if np.array_equal(update, f):
                break
            f = update
        held = np.minimum(f[:, None] * v, c)
        out[rows] = np.where(full[:, None] & (v > 0), c, held)
    return out


def _stretch(sun, share):
    """Each row of ``sun`` (rows, n) with its runs stretched or shrunk, in order, so that the true
    steps are ``share`` (rows,) of it: the states at the sub-step centres of the row's time mapped
    through its piecewise-linear warp (one weight per state); rows of a single state unchanged."""
    rows, n = sun.shape
    hit = sun.mean(axis=1)
    mixed = (hit > 0) & (hit < 1)
    safe = np.where(mixed, hit, 0.5)
    on = np.where(mixed, share / safe, 1.0)
    off = np.where(mixed, (1 - share) / (1 - safe), 1.0)
    ends = np.cumsum(np.where(sun, on[:, None], off[:, None]), axis=1)
    # Sub-step j's centre j + 0.5 lies in original sub-step i = #{ends <= j + 0.5}: count the ends
    # by the first centre past each (a bincount and a cumulative sum, no search).
    first = np.clip(np.ceil(ends - 0.5), 0, n).astype(np.int64)
    marks = np.bincount(
        (first + (n + 1) * np.arange(rows)[:, None]).ravel(), minlength=rows * (n + 1)
    )
    source = np.minimum(np.cumsum(marks.reshape(rows, n + 1)[:, :n], axis=1), n - 1)
    return np.take_along_axis(sun, source, axis=1)


def cloud_members(
    ghi,
    dhi,
    clear_ghi,
    cos_zenith,
    steps_per_interval: int,
    step_min: float,
    members: int,
    seed: int,
    cloud_cover=None,
) -> dict:
    """Members of light at every step with a weather file's interval means (module docstring).

    Parameters
    ----------
    ghi, dhi : array_like
        (n_days, n_intervals) mean global and diffuse horizontal irradiance of each interval of a
        weather file [W/m^2]; a negative or missing value counts as 0, a DHI above the GHI as the
        GHI.
    clear_ghi : array_like
        (n_days, n_steps) clear-sky GHI at every step [W/m^2], 0 at night; ``n_steps =
        n_intervals * steps_per_interval``, the steps filling the intervals in order.
    cos_zenith : array_like
        (n_days, n_steps) cosine of the solar zenith at every step [-].
    steps_per_interval : int
        Steps in an interval.
    step_min : float
        Length of a step [min].
    members : int
        Members to draw.
    seed : int
        Seed of the draws: member ``m`` draws from ``SeedSequence(seed).spawn(members)[m]``, so the
        same seed gives the same members, bit for bit, and a member does not depend on how many
        others are drawn.
    cloud_cover : array_like, optional
        (n_days, n_intervals) total sky cover [0..1] (tenths or oktas as a fraction: TMY3
        ``TotCld``, EPW total sky cover); where given and finite, the sun is obscured for this
        part of the interval [1]_ (within the beam's bounds), and a full cover makes it overcast;
        elsewhere the part follows from the interval's clear-sky index [4]_, and its chance of
        being overcast from that index and the sun's elevation [6]_.

    Returns
    -------
    dict
        ``ghi``, ``dni``, ``dhi``: (members, n_days, n_steps) [W/m^2]. Every member is 0 where the
        clear sky is; ``ghi = dni cos(zenith) + dhi`` at every step, ``dni >= 0`` (0 below
        :data:`MIN_COS_ZENITH`), ``0 <= dhi <= ghi``; ``ghi`` at most :data:`MAX_ENHANCEMENT`
        times the clear sky, times the interval's own clear-sky index too where that is above 1,
        and never above :data:`~foldopt.inputs.weather.downscale.MAX_CLEARSKY_INDEX` times it. Each interval
        lit by the clear sky keeps the file's mean GHI and DHI (to rounding), but where those
        bounds cut in, or where the sun stays within 1 deg of the horizon (its light then all
        diffuse).

    Raises
    ------
    ValueError
        For shapes that do not match, or a step, interval or member count that is not positive.
    """
    ghi = np.nan_to_num(np.asarray(ghi, dtype=float), nan=0.0)
    dhi = np.nan_to_num(np.asarray(dhi, dtype=float), nan=0.0)
    clear = np.nan_to_num(np.asarray(clear_ghi, dtype=float), nan=0.0)
    cosz = np.nan_to_num(np.asarray(cos_zenith, dtype=float), nan=0.0)
    spi, members = int(steps_per_interval), int(members)
    if spi < 1 or members < 1 or not step_min > 0:
        raise ValueError(
            f"steps_per_interval, members and step_min must be positive; got {spi}, {members}, "
            f"{step_min}"
        )
    if (
        ghi.ndim != 2
        or dhi.shape != ghi.shape
        or clear.shape != (ghi.shape[0], ghi.shape[1] * spi)
        or cosz.shape != clear.shape
    ):
        raise ValueError(
            f"ghi and dhi must be (n_days, n_intervals) and clear_ghi and cos_zenith (n_days, "
            f"n_intervals * {spi}); got {ghi.shape}, {dhi.shape}, {clear.shape}, {cosz.shape}"
        )
    n_days, n_int = ghi.shape
    clear = np.clip(clear, 0.0, None).reshape(n_days, n_int, spi)
    cosz = cosz.reshape(clear.shape)
    clear_mean = clear.mean(axis=-1)
    lit = clear_mean > 0
    eligible = (cosz >= MIN_COS_ZENITH) & (clear > 0)
    has_beam = eligible.any(axis=-1)
    glob = np.where(lit, np.clip(ghi, 0.0, None), 0.0)
    diffuse = np.minimum(np.clip(dhi, 0.0, None), glob)
    beam = np.where(has_beam, glob - diffuse, 0.0)
    diffuse = glob - beam  # the sun within 1 deg of the horizon all interval: all diffuse
    index = np.divide(glob, clear_mean, out=np.zeros_like(glob), where=lit)
    bound = np.minimum(MAX_ENHANCEMENT * np.maximum(1.0, index), MAX_CLEARSKY_INDEX)

    # 1. Sunshine fraction of each interval, within the beam's bounds.
    share = _sunshine(index)
    cover = None
    if cloud_cover is not None:
        cover = np.asarray(cloud_cover, dtype=float)
        if cover.shape != ghi.shape:
            raise ValueError(f"cloud_cover must be {ghi.shape}; got {cover.shape}")
        share = np.where(np.isfinite(cover), 1.0 - np.clip(np.nan_to_num(cover), 0.0, 1.0), share)
    cos_mean = np.divide(
        np.where(eligible, cosz, 0.0).sum(axis=-1),
        eligible.sum(axis=-1),
        out=np.ones_like(glob),
        where=has_beam,
    )
    most = beam / (SUNSHINE_DNI * cos_mean)
    room = bound * clear_mean - diffuse
    least = np.divide(beam, room, out=np.ones_like(beam), where=room > 0)
    share = np.where(beam > 0, np.clip(np.maximum(np.minimum(share, most), least), 0.0, 1.0), 0.0)
    oktas = (
        8.0 * np.where(np.isfinite(cover), np.clip(np.nan_to_num(cover), 0.0, 1.0), 1.0 - share)
        if cover is not None
        else 8.0 * (1.0 - share)
    )
    # The hour's chance of being overcast (no sunny state), from the file's cover where it gives one.
    elevation = np.degrees(np.arcsin(np.clip(cos_mean, 0.0, 1.0)))
    overcast = np.where((share > 0) & (share < 1), _overcast(index, elevation), 0.0)
    if cover is not None:
        overcast = np.where(
            np.isfinite(cover), (np.nan_to_num(cover) >= 1.0) & (share < 1), overcast
        )

    # 2. The sky's state: a chain through the lit intervals in order, on sub-steps of at most
    # CHAIN_STEP_MIN; after a dark interval (an hour of night decorrelates it) it starts afresh.
    sky = _envelope(
        np.divide(diffuse, clear_mean, out=np.zeros_like(diffuse), where=lit), lit, clear, spi
    )
    on = np.divide(
        beam,
        np.maximum(share, 1e-9) * cos_mean,
        out=np.zeros_like(beam),
        where=(share > 0) & has_beam,
    )
    direct = _envelope(on, on > 0, np.where(eligible, cosz, 0.0), spi)  # the DNI along cos(zenith)
    rows = np.flatnonzero(lit)  # chronological
    if rows.size == 0:
        zeros = np.zeros((members, n_days, n_int * spi))
        return {"ghi": zeros, "dni": zeros.copy(), "dhi": zeros.copy()}
    share, beam, diffuse, oktas, bound, overcast = (
        a.reshape(-1)[rows] for a in (share, beam, diffuse, oktas, bound, overcast)
    )
    clear, cosz, eligible, sky, direct = (
        a.reshape(-1, spi)[rows] for a in (clear, cosz, eligible, sky, direct)
    )
    fresh = np.ones(rows.size, dtype=bool)
    fresh[1:] = np.diff(rows) > 1
    sub = max(1, math.ceil(step_min / CHAIN_STEP_MIN - 1e-9))
    n, dt = spi * sub, step_min / sub
    rngs = [np.random.default_rng(child) for child in np.random.SeedSequence(seed).spawn(members)]
    speed = np.clip(
        np.stack([rng.gamma(SPEED_SHAPE, SPEED_SCALE, rows.size) for rng in rngs]), *SPEED_RANGE
    )
    # The chain redraws its state from (share, 1 - share) at the rate 2 u / MEAN_CHORD: its mean
    # run is then MEAN_CHORD / u when share is 1/2, as Bright et al.'s chords at speed u.
    redraw = 1.0 - np.exp(-2.0 * speed * 60.0 / MEAN_CHORD * dt)
    reset = np.stack([rng.random((rows.size, n)) for rng in rngs]) < redraw[..., None]
    state = np.stack([rng.random((rows.size, n)) for rng in rngs]) < share[:, None]
    reset[:, fresh, 0] = True
    reset = reset.reshape(members, -1)
    last = np.maximum.accumulate(np.where(reset, np.arange(reset.shape[1]), 0), axis=1)
    sun = np.take_along_axis(state.reshape(members, -1), last, axis=1).reshape(-1, n)
    del reset, state, last
    sun = _stretch(sun, np.tile(share, members)).reshape(members, rows.size, spi, sub).mean(axis=-1)
    noise = np.stack([rng.standard_normal((rows.size, spi)) for rng in rngs])
    covered = _overcast_hours(overcast, fresh, rngs)  # 3. (step 2 of the module docstring)
    hit = sun.mean(axis=-1)
    # no switch all interval, or overcast: the beam spread evenly
    uniform = (hit <= 0) | (hit >= 1) | covered
    sun = np.where(uniform[..., None], np.broadcast_to(share, hit.shape)[..., None], sun)

    # 4. The light: smooth diffuse, the beam on and off, noise, then each interval's means.
    okta = np.where(covered, 8.0, oktas)[..., None]
    sigma = sun * (NOISE_VISIBLE[0] + NOISE_VISIBLE[1] * okta) + (1 - sun) * (
        NOISE_OBSCURED[0] + NOISE_OBSCURED[1] * okta
    )
    factor = np.clip(1.0 + sigma * noise, 0.0, None)
    del noise, sigma
    cap = bound[:, None] * clear
    dhi_out = _fill(sky * factor, cap, diffuse)
    beam_out = sun * direct * factor
    none = (beam_out.sum(axis=-1) <= 0) & (beam > 0)
    beam_out = np.where(none[..., None], direct * factor, beam_out)
    beam_out = _fill(beam_out, cap - dhi_out, beam)
    # Beam the sunny steps cannot hold under the cap (sun drawn where the clear sky is low, at
    # sunrise) goes to the interval's other steps, evenly along the beam's curve.
    short = beam - beam_out.mean(axis=-1)
    if (short > 1e-9 * (beam + 1.0)).any():
        beam_out = beam_out + _fill(
            direct * factor, cap - dhi_out - beam_out, np.clip(short, 0.0, None)
        )
        # What the beam's steps cannot hold at all (the sun just clear of the horizon) is diffuse.
        short = np.clip(beam - beam_out.mean(axis=-1), 0.0, None)
        if (short > 1e-9 * (beam + 1.0)).any():
            dhi_out = dhi_out + _fill(sky * factor, cap - dhi_out - beam_out, short)
    out = {}
    for key, values in (
        ("ghi", dhi_out + beam_out),
        ("dhi", dhi_out),
        ("dni", np.divide(beam_out, cosz, out=np.zeros_like(beam_out), where=eligible)),
    ):
        full = np.zeros((members, n_days * n_int, spi))
        full[:, rows] = values
        out[key] = full.reshape(members, n_days, n_int * spi)
    return {key: out[key] for key in ("ghi", "dni", "dhi")}
