"""Reference implementations the core is checked and benchmarked against: the motion cones in
plain numpy (``cones``; also importable from here, as in the flat layout), the thesis' MNCP with
IPOPT (``mncp``) and the polyhedral-approximation report (``approx_error``)."""

from .cones import RefParams, classify_numpy_batch, generators_numpy, generators_numpy_batch

__all__ = ["RefParams", "classify_numpy_batch", "generators_numpy", "generators_numpy_batch"]
