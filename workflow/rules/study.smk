# A user's own study, defined in a YAML file (docs/study.md), run without editing any code:
#   snakemake -c2 study --config study=my_study.yaml
# study_simulate (one job per curve and chunk of the first axis, cusps refined) -> study_aggregate
# (one table, minima) -> study_plot (one figure per output, in the report under "Studies").
# The study is checked (restitution_workflow.study) while the workflow is read, before any job runs.


if STUDY_FILE is not None:
    from restitution_workflow.study import StudyError, front_page, load_study

    try:
        STUDY = load_study(STUDY_FILE)
    except StudyError as error:
        raise WorkflowError(str(error)) from None
    # The report's front page (workflow/report/workflow.rst) gets only snakemake.config: the
    # study's scene, units and axes reach it there (no rule reads this key).
    config["study_front"] = front_page(STUDY)
    STUDY_DIR = f"studies/{STUDY.name}"
    STUDY_PLOTS = {
        out: (f"figures/{STUDY_DIR}/{out}.png", f"figures/{STUDY_DIR}/{out}.pdf")
        for out in STUDY.outputs
    }

    rule study_simulate:
        """Solve one chunk of the first axis on one curve of the study, cusps refined."""
        input:
            study=str(STUDY_FILE),
            code=script_code("study_simulate.py"),
        output:
            table=f"results/{STUDY_DIR}/curve~{{curve}}/chunk_{{chunk}}.parquet",
        log:
            f"logs/{STUDY_DIR}/simulate/curve~{{curve}}/chunk_{{chunk}}.log",
        benchmark:
            f"logs/benchmarks/{STUDY_DIR}/simulate/curve~{{curve}}/chunk_{{chunk}}.tsv"
        wildcard_constraints:
            curve=r"\d+",
        conda:
            "../envs/restitution.yaml"
        threads: 2
        resources:
            mem_mb=1000,
            runtime=60,
        params:
            study=STUDY.raw,
        message:
            JOB_MESSAGE
        script:
            "../scripts/study_simulate.py"

    rule study_aggregate:
        """One table of the study from its chunks, and the COR minima of every curve."""
        input:
            chunks=expand(
                f"results/{STUDY_DIR}/curve~{{curve}}/chunk_{{chunk}}.parquet",
                curve=range(len(STUDY.curves)),
                chunk=range(STUDY.n_chunks),
            ),
            code=script_code("study_aggregate.py"),
        output:
            sweep=f"results/{STUDY_DIR}/sweep.parquet",
            minima=report(
                f"results/{STUDY_DIR}/minima.csv",
                caption="../report/study.rst",
                category="Studies",
                subcategory=STUDY.name,
                labels={
                    "study": STUDY.name,
                    "quantity": "table: COR minima per curve",
                },
            ),
        log:
            f"logs/{STUDY_DIR}/aggregate.log",
        benchmark:
            f"logs/benchmarks/{STUDY_DIR}/aggregate.tsv"
        conda:
            "../envs/restitution.yaml"
        params:
            study=STUDY.raw,
        message:
            JOB_MESSAGE
        script:
            "../scripts/study_aggregate.py"

    rule study_plot:
        """The study's standard plots: each output against the first axis, one curve per value
        of the second axis (png for the report, pdf for print)."""
        input:
            sweep=rules.study_aggregate.output.sweep,
            style="src/restitution/restitution.mplstyle",
            code=script_code("study_plot.py"),
        output:
            png=[
                report(
                    png,
                    caption="../report/study.rst",
                    category="Studies",
                    subcategory=STUDY.name,
                    labels={"study": STUDY.name, "quantity": out},
                )
                for out, (png, _pdf) in STUDY_PLOTS.items()
            ],
            pdf=[pdf for _png, pdf in STUDY_PLOTS.values()],
        log:
            f"logs/{STUDY_DIR}/plot.log",
        benchmark:
            f"logs/benchmarks/{STUDY_DIR}/plot.tsv"
        conda:
            "../envs/restitution.yaml"
        params:
            study=STUDY.raw,
        message:
            JOB_MESSAGE
        script:
            "../scripts/study_plot.py"

    rule study:
        """Target: the study named by --config study=FILE (its table, minima and plots)."""
        input:
            rules.study_aggregate.output,
            rules.study_plot.output,
        message:
            TARGET_MESSAGE

else:

    rule study:
        """Target: the study named by --config study=FILE (none given: says how)."""
        input:
            no_study_given,
        message:
            TARGET_MESSAGE
