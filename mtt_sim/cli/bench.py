"""`mtt-sim bench`: a tracker x scenario x seed grid, as a table of mean and 95% interval per metric."""

from __future__ import annotations

from mtt_sim.cli import grid
from mtt_sim.cli.arguments import UsageError, episode_overrides, loaded, scenario_keys


def add(subparsers) -> None:
    p = subparsers.add_parser("bench", help="a tracker x scenario x seed grid, as a table of mean and 95%% interval")
    p.add_argument("--scenarios", type=scenario_keys, required=True, help="comma-separated scenarios")
    p.add_argument("--by", choices=("scenario", "target"), default="scenario",
                   help="columns: scenarios, or ground-truth ids for the per-target metrics (CentreError, "
                        "Coverage, HiddenCentreError, Reacquired; hand-initialised trackers; one scenario)")
    grid.add_arguments(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from mtt_sim.metrics import PER_TARGET

    overrides = episode_overrides(args)
    loaded(args.scenarios, overrides)
    if args.by == "target" and set(args.metric) - set(PER_TARGET):
        raise UsageError("--metric", f"with --by target: {', '.join(PER_TARGET)} (per-target metrics)")
    if args.by == "target" and len(args.scenarios) > 1:
        raise UsageError("--scenarios", f"{','.join(args.scenarios)}: --by target makes a column per ground-truth id "
                                        "of one scenario; give one")
    title = ",".join(args.scenarios) if args.by == "target" else ""
    grid.check_plot(args)
    if args.plot and args.by == "target":
        raise UsageError("--plot", "plots columns of scenarios: leave out --by target")

    def table(records, metric) -> str:
        from mtt_sim.lab import experiment

        rows = experiment.summarize(records, metric, by=args.by)
        return experiment.markdown(rows, title) if rows else ""

    def plot(records):
        from mtt_sim.lab import plots

        plots.bench_plot(records, args.metric, args.plot)
    return grid.run(args, args.scenarios, overrides, None, table, plot)
