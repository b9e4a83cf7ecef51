"""Comparison tables (markdown) from results.json dicts, with the paper's numbers beside ours.

Each results dict carries "kind" (bench | context_ablation | sequence_suite) and "method" (planner
name); an optional "label" names the row (e.g. a sweep job's overrides). Cells read "ours (paper)";
methods the paper reports but we did not run are listed as paper-only reference rows. Used by the jobs'
results.md, the sweep callback and `python -m emopose.report`.
"""

from __future__ import annotations

from collections.abc import Sequence

from emopose.bench.paper import PAPER_CONTEXT, PAPER_METHOD_NAMES, PAPER_SEMANTIC, PAPER_SEQUENCE
from emopose.results import markdown_table

TIER_KEYS = ("easy", "medium", "hard", "overall")
CONTEXT_KEYS = ("with_history", "without_history", "gain")
SEQUENCE_KEYS = ("primary_class", "ordered_exact", "aligned_step", "multiset_f1", "anchor_recall",
                 "exact_variant", "exact_len2", "exact_len3", "exact_len4")
SEQUENCE_HEADERS = ("primary", "ordered exact", "aligned step", "multiset F1", "anchor recall",
                    "exact variant", "exact len2", "exact len3", "exact len4")


def fmt(stat: dict | tuple | None) -> str:
    """{mean, sd} or (mean, sd) -> '76.50±0.54' / '62.50' / '-'."""
    if stat is None:
        return "-"
    mean, sd = (stat.get("mean"), stat.get("sd")) if isinstance(stat, dict) else stat
    if mean is None:
        return "-"
    return f"{mean:.2f}" if sd is None else f"{mean:.2f}±{sd:.2f}"


def beside(ours: dict | None, paper: tuple | None) -> str:
    return fmt(ours) if paper is None else f"{fmt(ours)} ({fmt(paper)})"


def row_label(result: dict) -> str:
    """The row's name; a run that fell back more than its limit is marked, whatever the table."""
    label = result.get("label") or result.get("method", "?")
    if result.get("fallback_exceeded"):
        label += f" (FALLBACKS {100 * result['fallback_share']:.0f} %: not the planner's score)"
    return label


def _paper_only(table: dict, ran: set[str], keys: Sequence[str]) -> list[list]:
    rows = []
    for method, values in table.items():
        if method not in ran:
            name = PAPER_METHOD_NAMES.get(method, method)
            rows.append([f"paper: {name}", "-", "-", *[f"({fmt(values.get(k))})" for k in keys]])
    return rows


def bench_table(results: Sequence[dict]) -> str:
    rows = []
    for r in results:
        paper = PAPER_SEMANTIC.get(r["method"], {})
        acc = r["accuracy"]
        rows.append([row_label(r), r["n"], r["passes"],
                     *[beside(acc.get(t), paper.get(t)) for t in TIER_KEYS],
                     r.get("fallbacks", 0), r.get("failures", 0), _ms(r)])
    ran = {r["method"] for r in results}
    rows += [row + ["", "", ""] for row in _paper_only(PAPER_SEMANTIC, ran, TIER_KEYS)]
    header = ["method", "n", "passes", "easy", "medium", "hard", "overall", "fallbacks", "failures",
              "latency mean/p95 ms"]
    return markdown_table(header, rows)


def context_table(results: Sequence[dict]) -> str:
    rows = []
    for r in results:
        paper = PAPER_CONTEXT.get(r["method"], {})
        rows.append([row_label(r), r["n"], r["passes"], *[beside(r["accuracy"].get(k), paper.get(k))
                                                          for k in CONTEXT_KEYS],
                     r.get("failures", 0)])
    ran = {r["method"] for r in results}
    rows += [row + [""] for row in _paper_only(PAPER_CONTEXT, ran, CONTEXT_KEYS)]
    return markdown_table(["method", "n", "passes", "with history", "without history", "gain", "failures"],
                          rows)


def sequence_table(results: Sequence[dict]) -> str:
    rows = []
    for r in results:
        paper = PAPER_SEQUENCE.get(r["method"], {})
        m = r["metrics"]
        rows.append([row_label(r), r["n"], r["passes"],
                     *[beside(m.get(k), paper.get(k)) for k in SEQUENCE_KEYS],
                     f"{r['segmentation']['over_total']}/{r['segmentation']['under_total']}"])
    ran = {r["method"] for r in results}
    paper_rows = _paper_only(PAPER_SEQUENCE, ran, SEQUENCE_KEYS)
    rows += [row + ["(65/0)"] for row in paper_rows]
    return markdown_table(["method", "n", "passes", *SEQUENCE_HEADERS, "over/under (pooled)"], rows)


def _ms(result: dict) -> str:
    lat = result.get("latency_s") or {}
    if lat.get("mean") is None:
        return "-"
    return f"{1e3 * lat['mean']:.2f} / {1e3 * lat['p95']:.2f}"


TABLES = {"bench": ("Semantic benchmark: top-1 accuracy (%)", bench_table),
          "context_ablation": ("Dialogue-history ablation: accuracy (%)", context_table),
          "sequence_suite": ("Ordered multi-action planning (%)", sequence_table)}


def comparison_markdown(results: Sequence[dict], note: str = "") -> str:
    """One section per kind of result present; cells are 'ours (paper)', mean±SD over passes."""
    parts = []
    for kind, (title, render) in TABLES.items():
        group = [r for r in results if r.get("kind") == kind]
        if group:
            suites = sorted({r.get("suite", "") for r in group})
            parts.append(f"## {title}\n\nSuite: {', '.join(suites)}\n\n{render(group)}")
    if note:
        parts.append(note)
    return "\n\n".join(parts) + "\n"
