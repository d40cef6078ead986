"""A site's horizon, as a study gives it (:class:`Horizon`): (azimuth, elevation) points, or a file.

The model opens no file: a horizon file is read by :func:`foldopt.inputs.study_file.resolve_files`
(:func:`foldopt.inputs.horizon.read_horizon`) and its points handed to the validation as
:class:`~foldopt.inputs.sections.FilesRead`, as a load profile's file is.
"""

from __future__ import annotations

from typing import ClassVar

from pydantic import Field, ValidationInfo, field_validator, model_validator

from foldopt.inputs.horizon import horizon_profile
from foldopt.inputs.fields import FilesRead, StrictModel


class Horizon(StrictModel):
    """The horizon line around the panel: a hill, a building, a street canyon.

    ``site.horizon: FILE`` is ``{file: FILE}`` and ``site.horizon: [[az, el], ...]`` is
    ``{points: ...}``.

    Parameters
    ----------
    points : list of (float, float), optional
        (azimuth [deg from north, clockwise], elevation [deg]) pairs, linear between them around
        the circle (:func:`foldopt.inputs.horizon.horizon_profile`).
    file : str, optional
        Instead of ``points``: a PVGIS horizon file (JSON or CSV, as PVGIS's ``printhorizon``
        writes it) or a CSV with the header ``azimuth,elevation``; its points become ``points``
        where its loader read it (a file's site given with both holds the file's points).
    """

    LIST_SHORTHAND: ClassVar[str] = "points"  # foldopt.inputs.fields.list_valued_fields

    # The file first: its points are read from it (:meth:`_read_points`).
    file: str | None = None
    points: list[tuple[float, float]] | None = Field(None, validate_default=True)

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, value):
        if isinstance(value, str):
            return {"file": value}
        if isinstance(value, (list, tuple)):
            return {"points": value}
        return value

    @field_validator("points", mode="after")
    @classmethod
    def _read_points(cls, points, info: ValidationInfo):
        """A file's points, as its loader read them, where the file is read: they stand for the
        points (a study's data keep the file, not what was read from it)."""
        files = FilesRead.given(info)
        if info.data.get("file") is None or files is None or files.horizon_points is None:
            return points
        return [tuple(point) for point in files.horizon_points]

    @model_validator(mode="after")
    def _one_profile(self, info: ValidationInfo):
        if self.points is None and self.file is None:
            raise ValueError(
                "give the horizon as points (a list of [azimuth, elevation] in degrees) or as file"
            )
        files = FilesRead.given(info)
        if self.file is not None and files is not None and files.horizon_problem is not None:
            raise ValueError(files.horizon_problem)
        if self.points is not None:
            horizon_profile(self.points)  # ValueError: one line of what is wrong
        return self

    @property
    def read(self) -> bool:
        """Whether its points are known (a file's, once read)."""
        return self.points is not None

    def profile(self):
        """The horizon's azimuths and elevations [deg], sorted (:func:`foldopt.inputs.horizon.horizon_profile`).

        Returns
        -------
        tuple of numpy.ndarray
        """
        return horizon_profile(self.points)

    def describe(self) -> str:
        """The horizon in words: its file or points, and its highest elevation."""
        source = self.file if self.file is not None else f"{len(self.points)} points"
        top = max(elevation for _, elevation in self.points) if self.points else float("nan")
        return f"horizon {source} (up to {top:g} deg)"

    def flat(self) -> bool:
        """Whether the horizon hides nothing (every elevation 0): the open plain."""
        return max(elevation for _, elevation in self.points) <= 0.0
