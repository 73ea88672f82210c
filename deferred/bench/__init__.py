"""The benchmark harness (``deferred bench``, docs/guide/bench.md): the sweep and its runner
(:mod:`~deferred.bench.harness`), the scene variants it renders (:mod:`~deferred.bench.scenes`),
how a frame is timed (:mod:`~deferred.bench.timing`) and what is written of the results
(:mod:`~deferred.bench.report`)."""

from deferred.bench.harness import (
    Sweep,
    SweepProgress,
    check_output,
    check_sweep,
    describe_sweep,
    parse_counts,
    parse_light_paths,
    parse_pipelines,
    run_bench,
    sweep_points,
    sweep_runs,
    sweep_shells,
)
from deferred.bench.report import (
    BenchReport,
    BenchResult,
    crossovers,
    growth,
    noise,
    results_table,
    speedups,
    write_csv,
    write_json,
    write_plot,
)
from deferred.bench.scenes import shell_objects, with_extra_lights, with_shells
from deferred.bench.timing import cpu_frame, time_cpu, time_passes

__all__ = ["BenchReport", "BenchResult", "Sweep", "SweepProgress", "check_output", "check_sweep",
           "cpu_frame", "crossovers", "describe_sweep", "growth", "noise", "parse_counts",
           "parse_light_paths", "parse_pipelines", "results_table", "run_bench",
           "shell_objects", "speedups", "sweep_points", "sweep_runs", "sweep_shells",
           "time_cpu", "time_passes",
           "with_extra_lights", "with_shells", "write_csv", "write_json", "write_plot"]
