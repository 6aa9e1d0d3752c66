"""The model: what a user describes. The scene (``Chain``), its ranges (``ranges.RANGES``, the
one range table), the contact and link laws (``laws``) and units (``dimensional``). Nothing here
solves anything; every other layer imports from here."""
