"""Analyses built on the solvers: the paper's approximate COR model and its fit (``approx``,
``fitting``, ``special_points``), parameter sweeps with refined cusps (``sweeps``), the
(alpha, beta) grazing map (``cormap``), the design optimiser (``design``) and the COR against
the impact speed with Hertz contact (``speed``)."""
