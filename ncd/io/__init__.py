"""Layer 2, io: netCDF files with provenance (:mod:`.netcdf`), the units and names of
their variables (:mod:`.metadata`), and VTK / animation export (:mod:`.export`).
"""
