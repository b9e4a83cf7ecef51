"""The paper's non-LLM baselines: keyword, TF-IDF, Jaccard, SBERT centroids and chance."""
