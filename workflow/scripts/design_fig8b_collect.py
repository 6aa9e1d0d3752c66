"""Fig. 8(b) table: every design job's row in one table (results/design/designs.parquet)."""

import pandas as pd


def main(paths, output_path, logger) -> pd.DataFrame:
    from restitution.tables.io import read_table, write_table

    table = pd.concat([read_table(p) for p in paths], ignore_index=True)
    table = table.sort_values(["family", "n_masses"]).reset_index(drop=True)
    bad = table[table["status"] != "ok"]
    if len(bad):
        logger.warning("designs whose re-solved COR differs: %s", bad[["family", "n_masses"]])
    logger.info("%d designs", len(table))
    write_table(table, output_path)
    return table


if __name__ == "__main__":
    from _common import setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    main(list(snakemake.input.tables), snakemake.output.table, logger=log)  # noqa: F821
