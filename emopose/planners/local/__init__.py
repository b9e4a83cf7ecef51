"""The embedded offline planner: a fine-tuned sentence encoder with segmentation, class, variant and
relevance heads."""
