"""foldopt: design-space optimiser for twofold photovoltaic panels powering storage-less loads."""

from importlib import metadata

try:
    __version__ = metadata.version("foldopt")
except metadata.PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"
