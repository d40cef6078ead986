"""What a study's joint optimisation varies (:class:`Optimize`): the fold angle, the base tilt and
the base azimuth, any of them, each over bounds at a resolution.

The search itself is :func:`foldopt.engine.search.grid_search`; the study it runs over is
:func:`foldopt.studies.joint.optimize_plan`'s.
"""

from __future__ import annotations

import math

from pydantic import Field, field_validator, model_validator

from foldopt import names
from foldopt.inputs.fields import StrictModel, interval
from foldopt.inputs.reading import MAX_AXIS_VALUES, size_limit
from foldopt.names import FLAT_FOLD_ANGLE, canonical

#: Each variable's bounds where a study gives none: the fold angle the study's own grid; the tilt
#: from horizontal to vertical; the azimuth within 90 deg either side of the equator-facing one.
DEFAULT_TILT = (0.0, 90.0, 1.0)
DEFAULT_AZIMUTH_SPAN, DEFAULT_AZIMUTH_STEP = 90.0, 2.0
#: Designs of a search's grid (fold angles x tilts x azimuths) times its loads, as many as it may
#: evaluate and hold: the default grids hold 1.5 M, of which a search evaluates some 2 % (all of
#: them where nothing prunes); a step of 1e-9 deg made 1e15 and never ended.
MAX_DESIGNS = size_limit("MAX_DESIGNS", 20_000_000)


def grid_points(lo: float, hi: float, step: float) -> int:
    """Points of a grid from ``lo`` to ``hi`` by ``step``, always ending on ``hi`` (the last step
    shorter where ``step`` does not divide the span), counted without making it.

    Parameters
    ----------
    lo, hi, step : float
        ``step > 0``, ``hi >= lo``.

    Returns
    -------
    int
    """
    steps = math.floor((hi - lo) / step + 1e-9)
    return steps + 1 + (not math.isclose(lo + steps * step, hi, abs_tol=1e-9))


def vary_names(value) -> list[str]:
    """The variables an ``optimize.vary`` names: a list, or names joined by commas
    (``fold_angle, tilt``), each in foldopt's spelling where it is one of
    :data:`foldopt.names.OPTIMIZE_VARIABLES` (the study's validation names any other).

    Parameters
    ----------
    value : str or sequence of str

    Returns
    -------
    list of str

    Raises
    ------
    ValueError
        For a value that is no list of names.
    """
    items = [item.strip() for item in value.split(",")] if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)) or not all(isinstance(item, str) for item in items):
        raise ValueError(f"must be a list of {', '.join(names.OPTIMIZE_VARIABLES)}")
    spelled = []
    for item in items:
        try:
            spelled.append(canonical(item, names=names.OPTIMIZE_VARIABLES))
        except ValueError:
            spelled.append(item)
    return spelled


class Bounds(StrictModel):
    """One variable's range and resolution [deg]: ``min`` to ``max`` by ``step``, ending on ``max``.

    Azimuths may run below 0 or above 360 (a range across north, ``-90`` to ``90``); they are taken
    modulo 360.
    """

    min: interval(-360, 720, unit=" deg")
    max: interval(-360, 720, unit=" deg")
    step: interval(0, 90, lo_open=True, unit=" deg")

    @model_validator(mode="after")
    def _ordered(self):
        if self.min > self.max:
            raise ValueError(f"min ({self.min:g}) must not exceed max ({self.max:g})")
        return self

    def describe(self) -> str:
        """``min:max:step``, as the command line takes it."""
        return f"{self.min:g}:{self.max:g}:{self.step:g}"


class Optimize(StrictModel):
    """The joint optimisation of a study: which variables vary, over what, and how closely the search
    must find the optimum.

    Parameters
    ----------
    vary : list of str
        Of :data:`foldopt.names.OPTIMIZE_VARIABLES`; the others keep the study's value (the fold
        angle its best on the study's grid, the tilt and azimuth the panel's).
    fold_angle, tilt, azimuth : Bounds, optional
        Each variable's range; defaults: the study's ``fold_angles``, tilt 0 to 90 by 1, azimuth
        the equator-facing one +-90 by 2.
    tolerance_h : float
        [h] in [0, 1]: the search may miss a better design by at most this much of the objective
        (:func:`foldopt.engine.search.grid_search`); default 0.01 h (36 s).
    """

    vary: list[str] = Field(
        default_factory=lambda: list(names.OPTIMIZE_VARIABLES),
        min_length=1,
        max_length=3,
        description="fold_angle, tilt, azimuth: any of them",
    )
    fold_angle: Bounds | None = Field(None, description="default the study's fold_angles")
    tilt: Bounds | None = Field(None, description="default 0 to 90 by 1 deg")
    azimuth: Bounds | None = Field(None, description="default facing the equator +-90 by 2 deg")
    tolerance_h: interval(0, 1, unit=" h") = Field(0.01, description="what the search may miss [h]")

    @field_validator("vary", mode="before")
    @classmethod
    def _known(cls, value):
        """``vary: fold_angle, tilt`` is the list; each name in foldopt's spelling, once."""
        items = [canonical(item, names=names.OPTIMIZE_VARIABLES) for item in vary_names(value)]
        if len(set(items)) < len(items):
            raise ValueError("name each variable once")
        return items

    @field_validator("fold_angle")
    @classmethod
    def _fold_bounds(cls, bounds):
        if bounds is not None and not (0 < bounds.min and bounds.max <= FLAT_FOLD_ANGLE):
            raise ValueError(f"{bounds.describe()}: min and max must be in (0, 180] deg")
        return bounds

    @field_validator("tilt")
    @classmethod
    def _tilt_bounds(cls, bounds):
        if bounds is not None and not (0 <= bounds.min and bounds.max <= 90):
            raise ValueError(f"{bounds.describe()}: min and max must be in [0, 90] deg")
        return bounds

    @field_validator("azimuth")
    @classmethod
    def _azimuth_bounds(cls, bounds):
        """Azimuths repeat after a turn: a wider range searches each direction again."""
        if bounds is not None and bounds.max - bounds.min > 360:
            raise ValueError(
                f"{bounds.describe()}: spans {bounds.max - bounds.min:g} deg; at most 360 (azimuths "
                f"repeat after a turn)"
            )
        return bounds

    def range_of(self, name: str, default: tuple) -> tuple:
        """A variable's ``(min, max, step)`` [deg]: its bounds, or ``default`` where none are set.

        Parameters
        ----------
        name : str
            One of :data:`foldopt.names.OPTIMIZE_VARIABLES`.
        default : tuple of float
        """
        bounds = getattr(self, name)
        return (bounds.min, bounds.max, bounds.step) if bounds is not None else default

    def searched_range(self, name: str, fold_angles, equator: float = 180.0) -> tuple:
        """A variable's ``(min, max, step)`` [deg] as the search walks it: its bounds, or the
        default (the fold angle the study's grid, the tilt :data:`DEFAULT_TILT`, the azimuth
        ``equator`` +- :data:`DEFAULT_AZIMUTH_SPAN` by :data:`DEFAULT_AZIMUTH_STEP`).

        Parameters
        ----------
        name : str
            One of :data:`foldopt.names.OPTIMIZE_VARIABLES`.
        fold_angles : foldopt.inputs.sections.FoldAngles
            The study's grid.
        equator : float, default 180
            The equator-facing azimuth [deg].
        """
        defaults = {
            "fold_angle": (fold_angles.start, fold_angles.stop, fold_angles.step),
            "tilt": DEFAULT_TILT,
            "azimuth": (
                equator - DEFAULT_AZIMUTH_SPAN,
                equator + DEFAULT_AZIMUTH_SPAN,
                DEFAULT_AZIMUTH_STEP,
            ),
        }
        return self.range_of(name, defaults[name])

    def size_problem(self, fold_angles) -> str | None:
        """Why the search's grid is too large to search, naming the largest varied variable's
        setting: more designs than :data:`MAX_DESIGNS`, or one variable with more values than
        ``FOLDOPT_MAX_AXIS_VALUES`` (each variable's near-optimal region is evaluated along its
        whole grid).

        Parameters
        ----------
        fold_angles : foldopt.inputs.sections.FoldAngles
            The study's grid, the fold angle's where its bounds are not set.

        Returns
        -------
        str or None
            ``field = value: problem``, or None for a grid within the limits.
        """
        counts = {name: grid_points(*self.searched_range(name, fold_angles)) for name in self.vary}
        designs = math.prod(counts.values())
        largest = max(counts, key=counts.get)
        bounds = getattr(self, largest)
        # only the fold angle's default grid varies
        setting = (
            f"optimize.{largest} = {bounds.describe()}"
            if bounds is not None
            else f"fold_angles.step = {fold_angles.step:g}"
        )
        nouns = {"fold_angle": "fold angles", "tilt": "tilts", "azimuth": "azimuths"}
        if counts[largest] > MAX_AXIS_VALUES:
            return (
                f"{setting}: {counts[largest]:,} {nouns[largest]}; the limit is {MAX_AXIS_VALUES:,} values a "
                f"range (a coarser step, or FOLDOPT_MAX_AXIS_VALUES)"
            )
        if designs > MAX_DESIGNS:
            return (
                f"{setting}: {' x '.join(f'{counts[name]:,} {nouns[name]}' for name in counts)} = "
                f"{designs:.2g} designs to search; the limit is {MAX_DESIGNS:,} (a coarser step, or "
                f"FOLDOPT_MAX_DESIGNS)"
            )
        return None

    def idle_settings(self) -> list[str]:
        """``optimize.name = ...: why`` for the bounds of a variable that does not vary."""
        return [
            f"optimize.{name} = {getattr(self, name).describe()}: is only used where optimize.vary names "
            f"{name}"
            for name in names.OPTIMIZE_VARIABLES
            if getattr(self, name) is not None and name not in self.vary
        ]
