"""Support code of the Snakemake workflow (not part of the installed ``restitution`` package):
the configuration check (``config_check``), user studies (``study``) and the benchmark harness
(``bench``). Importable from a source checkout (``make env`` installs it in editable mode)."""
