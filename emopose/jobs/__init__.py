"""Jobs: what an experiment does with a Run: its resources, session and turn runner
(conf/experiment/*.yaml sets `job`; emopose/resources.py)."""
