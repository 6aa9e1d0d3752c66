"""Benchmarks and the hard-case scene suite (issue #7).

``restitution_workflow.bench.scenes`` defines the fixed suite of hard scenes, each with a reference
COR
and contact count from an independent method (``benchmarks/reference_values.py``); the
work-precision harness and the ``hard`` pytest suite both run over it.
"""
