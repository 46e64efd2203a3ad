"""The package version, read by the provenance attributes of every netCDF file."""
__version__ = "0.1.0"
