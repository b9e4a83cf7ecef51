"""The paper's reported numbers (Tables semantic and extensions), keyed by our planner names.

Used to print the paper's value beside ours in every results table. Means in %, SD where reported
(None for deterministic entries). Planner names without a paper row simply get no paper column.
"""

from __future__ import annotations

# Table semantic: top-1 accuracy (%) on EmoPose-Bench, {tier: (mean, sd)}.
PAPER_SEMANTIC: dict[str, dict[str, tuple[float, float | None]]] = {
    "llm": {"easy": (98.25, 0.52), "medium": (70.50, 0.81), "hard": (60.75, 0.81), "overall": (76.50, 0.54)},
    "direct_label": {"easy": (95.00, 0.63), "medium": (67.13, 2.24), "hard": (54.13, 1.14),
                     "overall": (72.08, 0.74)},
    "sbert_centroids": {"easy": (97.50, None), "medium": (58.75, None), "hard": (52.50, None),
                        "overall": (69.58, None)},
    "keyword": {"easy": (62.50, None), "medium": (16.88, None), "hard": (11.25, None),
                "overall": (30.21, None)},
    "tfidf": {"easy": (26.88, None), "medium": (22.50, None), "hard": (23.13, None),
              "overall": (24.17, None)},
    "jaccard": {"easy": (21.25, None), "medium": (17.50, None), "hard": (18.13, None),
                "overall": (18.96, None)},
    "chance": {"easy": (12.50, None), "medium": (12.50, None), "hard": (12.50, None),
               "overall": (12.50, None)},
}

PAPER_METHOD_NAMES = {
    "llm": "Ordered planning (ours)", "direct_label": "Direct-label GPT-5.5",
    "sbert_centroids": "Sentence-BERT, Easy centroids", "keyword": "Keyword rules",
    "tfidf": "TF-IDF descriptions", "jaccard": "Jaccard descriptions", "chance": "Uniform chance",
}

# Table extensions: the full planner (GPT-5.5, structured prompt), five passes.
PAPER_CONTEXT = {"llm": {"with_history": (96.69, 0.36), "without_history": (95.00, 1.06),
                         "gain": (1.69, 0.98)}}
PAPER_SEQUENCE = {
    "llm": {
        "primary_class": (97.75, 0.68), "ordered_exact": (91.50, 0.71), "aligned_step": (95.49, 0.31),
        "multiset_f1": (97.94, 0.28), "anchor_recall": (99.98, 0.03), "exact_variant": (44.88, 0.70),
        "exact_len2": (96.75, None), "exact_len3": (94.00, None), "exact_len4": (81.25, None),
        # Pooled over five passes (1,600 plans): 65 over-segmented, none under-segmented.
        "over_total": (65, None), "under_total": (0, None),
    }
}
