"""`mtt-sim sweep`: a stress curve, one scenario with one parameter over several values, per tracker."""

from __future__ import annotations

import json

from mtt_sim.cli import grid
from mtt_sim.cli.arguments import SCENARIO_HELP, UsageError, episode_overrides, loaded, scenario_key, toml_value


def add(subparsers) -> None:
    p = subparsers.add_parser("sweep", help="a stress curve: one scenario, one parameter over several values")
    p.add_argument("scenario", type=scenario_key, help=SCENARIO_HELP)
    p.add_argument("--param", required=True, metavar="KEY=V1,V2,...", help="e.g. sensor.clutter_rate=0,2,5,10,20")
    grid.add_arguments(p)
    p.set_defaults(func=run)


def run(args) -> int:
    key, sep, values = args.param.partition("=")
    if not sep or not key or not values:
        raise UsageError("--param", f"{args.param!r}: expected key=v1,v2,..., e.g. sensor.clutter_rate=0,5,10")
    values = [toml_value(v) for v in values.split(",")]
    repeated = next((v for i, v in enumerate(values) if v in values[:i]), None)
    if repeated is not None:
        raise UsageError("--param", f"{args.param!r}: the value {repeated!r} is given twice; each value once")
    overrides = episode_overrides(args)
    loaded([args.scenario], overrides)
    loaded([args.scenario], overrides, "--param", [{key: v} for v in values])
    grid.check_plot(args)

    def table(records, metric) -> str:
        from mtt_sim.lab import experiment

        rows = experiment.summarize(records, metric, by="config")
        for r in rows:
            r["column"] = f"{key.split('.')[-1]}={json.loads(r['column'])[key]}"
        return experiment.markdown(rows, f"{args.scenario}, sweeping {key}") if rows else ""

    def plot(records):
        from mtt_sim.lab import plots

        plots.sweep_plot(records, args.scenario, key, values, args.metric, args.plot)
    return grid.run(args, [args.scenario], overrides, [{key: v} for v in values], table, plot)
