"""Scene tables: strict reading of a table of scenes (``scene_table``, with the column-wise fast
screen of linear chains in ``linear_rows``) and parquet/CSV input and output with provenance
(``io``)."""
