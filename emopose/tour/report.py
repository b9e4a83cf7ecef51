"""What a tour produced: per-stop navigation and gestures, the exchanges with visitors, totals."""

from __future__ import annotations

from collections import Counter
from dataclasses import asdict, dataclass, field

from emopose.contract import EventKind
from emopose.results import markdown_table


@dataclass
class StopResult:
    name: str
    reached: bool
    leg_s: float
    pauses: int
    odometry_error_m: float  # odometry pose vs the stop (what the robot believes)
    true_error_m: float | None  # simulated ground truth vs the stop (None on the robot)
    yaw_error_deg: float
    within_tolerance: bool
    gestures_while_walking: int = 0
    narration: list[str] = field(default_factory=list)
    interruptions: int = 0
    gestures: list[str] = field(default_factory=list)  # started during the narration (and answers)
    aims: list[dict] = field(default_factory=list)

    def add_events(self, events, aims) -> None:
        self.gestures = [e.name for e in events if e.kind == EventKind.STARTED]
        self.aims = [asdict(a) for a in aims]


@dataclass
class Exchange:
    question: str
    where: str
    t: float
    base_moving_when_asked: bool
    answer: str = ""
    image_attached: bool = False
    gestures: list[str] = field(default_factory=list)
    aborted: bool = False


@dataclass
class TourReport:
    name: str
    stops: list[StopResult] = field(default_factory=list)
    exchanges: list[Exchange] = field(default_factory=list)
    aborted: bool = False
    ended_at_rest: bool = False
    sim_time_s: float = 0.0
    gesture_events: dict = field(default_factory=dict)
    unasked: list[str] = field(default_factory=list)

    def finish(self, events, aborted: bool, unasked: list[str]) -> None:
        self.aborted, self.unasked = aborted, unasked
        self.gesture_events = dict(Counter(e.kind for e in events if e.kind != EventKind.STATE))

    @property
    def max_error_m(self) -> float:
        errors = [s.true_error_m if s.true_error_m is not None else s.odometry_error_m for s in self.stops]
        return max(errors, default=float("nan"))

    def as_dict(self) -> dict:
        return {
            "tour": self.name,
            "stops_reached": sum(s.reached for s in self.stops),
            "stops_within_tolerance": sum(s.within_tolerance for s in self.stops),
            "max_position_error_m": self.max_error_m,
            # a co-articulated gesture ends "cut" after its stroke: executed once its stroke arrived
            "gestures_executed": self.gesture_events.get("completed", 0) + self.gesture_events.get("cut", 0),
            "gestures_stroked": self.gesture_events.get("stroke", 0),
            "gestures_started": self.gesture_events.get("started", 0),
            "gesture_events": self.gesture_events,
            "interruptions_handled": len(self.exchanges),
            "aborted": self.aborted,
            "ended_at_rest": self.ended_at_rest,
            "sim_time_s": self.sim_time_s,
            "stops": [asdict(s) for s in self.stops],
            "exchanges": [asdict(e) for e in self.exchanges],
            "unasked": self.unasked,
        }

    def markdown(self) -> str:
        rows = [[s.name, "yes" if s.reached else "NO", _cm(s.true_error_m), _cm(s.odometry_error_m),
                 f"{s.yaw_error_deg:.1f}", len(s.gestures), s.interruptions,
                 ", ".join(_aim(a) for a in s.aims) or "-"] for s in self.stops]
        table = markdown_table(["stop", "reached", "error (true) cm", "error (odom) cm", "yaw err deg",
                                "gestures", "questions", "aimed at"], rows)
        talk = markdown_table(["where", "question", "answer", "image", "gestures"],
                              [[e.where, e.question, e.answer, "yes" if e.image_attached else "no",
                                ", ".join(e.gestures) or "-"] for e in self.exchanges])
        d = self.as_dict()
        return (f"# Tour '{self.name}'\n\n{table}\n\n## Questions\n\n{talk}\n\n"
                f"Stops reached {d['stops_reached']}/{len(self.stops)}, max position error "
                f"{self.max_error_m * 100:.1f} cm; {d['gestures_executed']} gestures executed; "
                f"{len(self.exchanges)} interruptions handled; aborted: {self.aborted}; "
                f"ended at rest: {self.ended_at_rest}; sim time {self.sim_time_s:.1f} s.")


def _aim(aim: dict) -> str:
    kept = "" if aim["applied"] else " (library motion kept)"
    return f"{aim['target']} {aim['error_deg']:.1f} deg{kept}"


def _cm(value: float | None) -> str:
    return "-" if value is None else f"{value * 100:.1f}"
