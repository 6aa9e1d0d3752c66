"""Solve one chunk of a user study's first axis on one of its curves, cusps refined.

The study comes as the rule's params (the checked study mapping); it is checked again here
(cheap) so that the script can be called on its own. Output: the chunk's table with provenance.
"""


def main(study_mapping: dict, curve_index: int, chunk: int, output_path, logger):
    from restitution.tables.io import write_table
    from restitution_workflow.study import check_study, solve_curve

    study = check_study(study_mapping)
    curve = float(study.curves[curve_index])
    table = solve_curve(study, curve, chunk, logger)
    table["curve_index"] = curve_index
    write_table(
        table,
        output_path,
        config={"study": study_mapping, "curve": curve, "chunk": chunk},
    )


if __name__ == "__main__":
    from _common import Timer, setup

    log = setup(snakemake)  # noqa: F821 (injected by Snakemake)
    with Timer(log, "study chunk"):
        main(
            snakemake.params.study,  # noqa: F821
            int(snakemake.wildcards.curve),  # noqa: F821
            int(snakemake.wildcards.chunk),  # noqa: F821
            snakemake.output.table,  # noqa: F821
            log,
        )
