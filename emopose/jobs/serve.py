"""+experiment=serve: the web UI on a live robot (chat, simulation view, Pose Studio).

The control loop runs on its own thread in real time for as long as the server runs, at the raised
priority run.rt_priority asks for (see ControlLoop.start); turns are planned on a worker thread.
uvicorn owns the main thread until Ctrl-C or SIGTERM (it shuts down gracefully on both; see
emopose/stop_signals.py), then everything is released (the session's close() stops the loop and the
backend) and the results are written, the loop's missed deadlines, stalls and lateness among them.
Settings are validated when the job is built, so a bad serve.* value (say, a network bind without a
token) stops before anything starts.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

from emopose.build import ConfigError
from emopose.resources import Run
from emopose.results import JobOutput
from emopose.web.settings import ServeSettings

log = logging.getLogger(__name__)


@dataclass
class ServeJob:
    serve: dict = field(default_factory=dict)
    render: bool = True  # false: no MuJoCo frames anywhere (stick figure only)
    rt_priority: int = 0  # run.rt_priority: SCHED_FIFO priority of the control loop's thread; 0 leaves it

    def __post_init__(self) -> None:
        if not 0 <= self.rt_priority <= 99:  # the OS would refuse it and the loop fall back unnoticed
            raise ValueError(f"run.rt_priority={self.rt_priority}: a SCHED_FIFO priority is 1-99 (0: normal)")
        self.settings = ServeSettings.from_config(self.serve)

    def __call__(self, run: Run) -> JobOutput:
        res = run.resources
        if not res.clock.realtime:
            raise ConfigError("serve needs real time: run with run.clock=monotonic "
                              "(the serve experiment sets it)")
        import uvicorn  # the web extras load only when serving

        from emopose.web.app import create_app
        from emopose.web.live import open_session

        # The renderer first: its setup holds the GIL.
        session = open_session(run, self.settings, render=self.render)
        loop = run.session.open()
        try:
            loop.start(self.rt_priority)
            app = create_app(session)
            s = self.settings
            print(f"EmoPose UI: http://{s.host}:{s.port}/  (Pose Studio: /studio)"
                  + ("  -- open it with ?token=<serve.token>" if s.token else ""), flush=True)
            uvicorn.run(app, host=s.host, port=s.port, ws_max_size=s.max_ws_message_bytes,
                        log_level="warning", access_log=False)
        finally:
            session.close()
            loop.stop()
        turns = [m for m in session.log_since(0) if m["type"] == "turn"]
        results = {"turns": len(turns), "backend": res.backend.name, "planner": res.planner.name,
                   "library_version": res.library.version, "loop": loop.stats.summary()}
        return results, (f"Served {len(turns)} turn(s) on {res.backend.name} with planner "
                         f"{res.planner.name}; control loop {results['loop']}")
