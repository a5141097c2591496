"""Visualization: figures and animations with matplotlib (``plotting``) and the browser view of a
plan (``viewer``)."""
