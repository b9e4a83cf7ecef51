"""Jobs: what an experiment does with a run context (conf/experiment/*.yaml sets `job`)."""
