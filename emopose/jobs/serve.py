"""+experiment=serve: the web UI on a live robot (chat, simulation view, Pose Studio).

The control loop runs on its own thread in real time for as long as the server runs, at the raised
priority run.rt_priority asks for (see ControlLoop.start); turns are planned on a worker thread.
The port is checked when the job is built, before the planner and the robot load, so a second serve on
a busy port stops at once (one line, exit 2); the socket is bound and listening before the banner is
printed, so a client following the banner reaches this server. uvicorn owns the main thread until
Ctrl-C or SIGTERM (it shuts down gracefully on both, then raises the signal again; see
emopose/stop_signals.py); everything is released (the session's close() stops the loop and the backend),
the results are written (every turn counted, emopose/web/serve_tally.py) and the exit status says which
signal ended it (130 SIGINT, 143 SIGTERM). Settings are validated when the job is built, so a bad
serve.* value (say, a network bind without a token) stops before anything starts.
"""

from __future__ import annotations

import logging
import socket
from dataclasses import dataclass, field

from emopose.build import ConfigError
from emopose.contract import USABLE_SOURCES
from emopose.execution.priority import check_rt_priority
from emopose.resources import Run
from emopose.results import JobFailure, JobOutput, markdown_table
from emopose.web.serve_tally import SOURCE_WORDS
from emopose.web.settings import ServeSettings

log = logging.getLogger(__name__)


@dataclass
class ServeJob:
    serve: dict = field(default_factory=dict)
    render: bool = True  # false: no MuJoCo frames anywhere (stick figure only)
    rt_priority: int = 0  # run.rt_priority: SCHED_FIFO priority of the control loop's thread; 0 leaves it

    def __post_init__(self) -> None:
        check_rt_priority(self.rt_priority)
        self.settings = ServeSettings.from_config(self.serve)
        listen(self.settings).close()  # busy: say so now, not after the heavy parts have loaded

    def __call__(self, run: Run) -> JobOutput:
        res = run.resources
        if not res.clock.realtime:
            raise ConfigError("serve needs real time: run with run.clock=monotonic "
                              "(the serve experiment sets it)")
        import uvicorn  # the web extras load only when serving

        from emopose.web.app import create_app
        from emopose.web.live import open_session

        listener = listen(self.settings)  # taken by now (another server started meanwhile): ConfigError
        session = open_session(run, self.settings, render=self.render)  # the renderer first: it holds the GIL
        loop, stopped_by = run.session.open(), None
        try:
            s = self.settings
            config = uvicorn.Config(create_app(session), ws_max_size=s.max_ws_message_bytes,
                                    log_level="warning", access_log=False)
            loop.start(self.rt_priority)  # after everything is loaded: it freezes the survivors for the GC
            print(f"EmoPose UI: http://{s.host}:{s.port}/  (Pose Studio: /studio)"
                  + ("  -- open it with ?token=<serve.token>" if s.token else ""), flush=True)
            try:
                uvicorn.Server(config).run(sockets=[listener])
            except KeyboardInterrupt as interrupt:  # uvicorn stopped gracefully, then raised the signal
                stopped_by = interrupt
        finally:
            session.close()
            loop.stop()
            listener.close()
        output = served(run, session, loop.stats.summary())
        if stopped_by is not None:
            raise JobFailure(*output, stopped_by)  # the results are written, the signal sets the status
        return output


def listen(settings: ServeSettings) -> socket.socket:
    """A socket bound and listening on serve.host:serve.port; a port in use is a one-line ConfigError."""
    try:
        family, kind, proto, _, address = socket.getaddrinfo(settings.host, settings.port,
                                                             type=socket.SOCK_STREAM)[0]
        listener = socket.socket(family, kind, proto)
    except OSError as exc:
        raise ConfigError(f"serve.host={settings.host}: cannot listen there ({exc})") from None
    try:
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn binds
        listener.bind(address)
        listener.listen(2048)
    except OSError as exc:
        listener.close()
        raise ConfigError(f"serve.port={settings.port}: {settings.host}:{settings.port} is in use "
                          f"({exc.strerror}); stop the other server or choose another serve.port") from None
    return listener


def served(run: Run, session, loop: dict) -> JobOutput:
    """results.json (every turn counted, the page's log is bounded) and results.md (a per-turn table)."""
    res, tally, dialogue, clients = run.resources, session.tally, run.runner.dialogue, session.clients
    history = {"window_turns": dialogue.window.turns, "window_tokens": dialogue.window.tokens,
               "messages_in_window": len(dialogue.messages), "messages_total": dialogue.total,
               "turns_dropped": dialogue.dropped_turns}
    results = {**tally.results(), "backend": res.backend.name, "planner": res.planner.name,
               "library_version": res.library.version, "history": history,
               "clients": clients.counters(), "loop": loop}
    sources = [[source, SOURCE_WORDS[source], n, "" if source in USABLE_SOURCES else "yes"]
               for source, n in sorted(tally.sources.items())]
    markdown = "\n\n".join([
        f"# Served {results['turns']} turn(s) on {res.backend.name} with planner {res.planner.name}",
        markdown_table(["", "count"], [
            ["turns", results["turns"]], ["fallbacks", results["fallbacks"]],
            ["planner calls failed", results["planner_failures"]],
            ["replies stopped early", results["replies_stopped"]], ["interrupts", results["interrupts"]],
            ["pages accepted / refused", f"{clients.accepted} / {clients.refused}"],
            ["history turns dropped", history["turns_dropped"]],
            ["loop missed deadlines / ticks", f"{loop['missed_deadlines']} / {loop['ticks']}"]]),
        "## Plan sources\n\n" + markdown_table(["source", "meaning", "turns", "fallback"], sources),
        "## Turns\n\n" + tally.markdown()])
    return results, markdown
