"""The scenes of the paper's figures: building, simulating and exploring them.

One module per figure; each turns a config section into xarray Datasets.
"""
