"""Rules across fields that a request's JSON schema cannot state, written into each operation's
OpenAPI description.

A JSON schema bounds each field and can say "exactly one of", "not both" or "if this then
that" (the request models do: ``model.params.given``), but not a rule between two numbers or
one that needs the engine: that two gears mesh without involute interference, that a range
runs from low to high, that a run fits the compute budget. Such a request is schema-valid and
still refused with a 422 problem naming the field. Each operation that has such rules says so
in its description, in the words ``schemathesis.toml`` quotes beside the operations for which it
accepts a 422 to schema-valid data (``tests/test_fuzz_config.py`` holds the two together).
"""

from __future__ import annotations

from typing import Any

DESIGN = (
    "the design's gears mesh (no involute interference, base radii in the tooth ratio), its "
    "speed_range runs from low to high and each tolerance stays inside its field's range"
)
SYNC_BUDGET = "the analysis fits the synchronous compute budget (max_sync_steps)"
JOB_BUDGET = "the job fits the compute budget of one job (max_job_steps)"
AXES = (
    "an axis' stop differs from its start (and equals it for one point) and every corner of the "
    "grid is a valid design"
)
RECORD = "the record holds enough revolutions at the given speed for an order reading"
DERIVED = "the dimensionless parameters derived from the physical data stay within their bounds"
UPLOAD = (
    "the uploaded text holds a series of numbers, and the rate and speed given in the query read "
    "as quantities (a number with a unit, or a bare number in Hz or rad/s, in its plausible range)"
)

CROSS_FIELD_RULES: dict[str, tuple[str, ...]] = {
    "post_analysis_v1_analyses_post": (DESIGN, SYNC_BUDGET),
    "post_analysis_plot_v1_analyses_plot_post": (DESIGN, SYNC_BUDGET),
    "post_basins_plot_v1_analyses_basins_plot_post": (DESIGN, SYNC_BUDGET),
    "post_campbell_v1_analyses_campbell_post": (DESIGN,),
    "post_campbell_plot_v1_analyses_campbell_plot_post": (DESIGN,),
    "post_basins_v1_basins_post": (DESIGN, JOB_BUDGET),
    "post_design_conversion_v1_conversions_design_post": (DESIGN,),
    "post_conversion_v1_conversions_physical_post": (DERIVED,),
    "post_melnikov_v1_melnikov_post": (DESIGN,),
    "post_remedies_v1_remedies_post": (DESIGN, JOB_BUDGET),
    "post_robustness_v1_robustness_post": (DESIGN, AXES, JOB_BUDGET),
    "post_runup_v1_runups_post": (DESIGN, JOB_BUDGET),
    "post_signal_v1_signals_post": (DESIGN, RECORD),
    "post_signal_v1_signals_jobs_post": (DESIGN, RECORD),
    "post_signal_plot_v1_signals_plot_post": (DESIGN, RECORD),
    "post_signal_upload_v1_signals_upload_post": (UPLOAD, RECORD),
    "post_signal_upload_plot_v1_signals_upload_plot_post": (UPLOAD, RECORD),
    "post_sweep_v1_sweeps_post": (DESIGN, AXES, JOB_BUDGET),
    "post_thresholds_v1_thresholds_post": (DESIGN,),
    "post_threshold_plot_v1_thresholds_plot_post": (DESIGN,),
}
"""Operation id -> its rules across fields (refused with a 422 naming the field)."""

LEAD = "Rules across fields that the schema cannot state (a request breaking one is refused "\
    "with 422, naming the field): "  # fmt: skip


def add_cross_field_rules(spec: dict[str, Any]) -> dict[str, Any]:
    """``spec`` with each operation of ``CROSS_FIELD_RULES`` stating its rules at the end of
    its description; returned for chaining (changed in place)."""
    for ops in spec.get("paths", {}).values():
        for op in ops.values():
            rules = CROSS_FIELD_RULES.get(op.get("operationId")) if isinstance(op, dict) else None
            if rules:
                text = LEAD + "; ".join(rules) + "."
                op["description"] = f"{op['description']}\n\n{text}" if op.get("description") \
                    else text  # fmt: skip
    return spec
