"""Stimulus sets: one spec → many labelled stimuli, on one machine or a Dask cluster."""
