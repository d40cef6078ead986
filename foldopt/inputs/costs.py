"""The panel sizing's constants (Shin et al. Sec. IV-A), written once: the command line, the API and
:mod:`foldopt.studies.sizing` read them. A leaf module, so that the command line's help stays fast.

Not :mod:`foldopt.inputs.costs_section`: that is a study's ``costs`` section, its own prices of
panel, buffer, hinge and tracker drive for the least-cost panel and buffer
(:mod:`foldopt.studies.least_cost`); these are ``foldopt size``'s paper constants."""

#: Grid energy price [$/kWh], Shin et al. Sec. IV-A.
C_GRID = 0.22
#: Panel lifetime [years], Shin et al. Sec. IV-A.
LIFETIME_YEARS = 20.0
#: Panel cost [$/m^2]: Shin et al. do not state it; the 0.108 m^2 optimum of their flat panel implies it.
PAPER_COST_PER_M2 = 164.0
#: Days a year like the study's day.
DAYS_PER_YEAR = 365.0
