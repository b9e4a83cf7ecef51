"""The robot-side gesture sequencer (paper Fig. sequencer): one active trajectory, a FIFO queue; states
and transitions: State (gesture_command.py). `step(now)` (50 Hz) returns the target to publish; every
transition starts from the latest published pose (no jumps); submit/interrupt are thread-safe; time is
the caller's `now`. `preempt_after_s` (off by default): a command overdue by that much cuts the running
motion short with a blend. Timed commands (turn/timeline.py) fix every keyframe's time: one starts at its
release from the pose published then, preempting (CUT) a motion still running, lengthening only what the
speed bound forbids. After a stall a running gesture catches up (TrajectoryBuilder.catch_up) or is
STOPPED when its stroke would be over `stall_stop_late_s` late. STROKE: the arm within STROKE_TOLERANCE of
the stroke-start keyframe, as commanded or, where the backend measures its joints (`observe`, the
StrokeWatch), as measured, the command's arrival then being STROKE_COMMANDED. Between gestures the arms
go to the current posture, where they may breathe (posture.py: the posture layer).
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from emopose.contract import EventKind
from emopose.execution.bounded_log import BoundedLog
from emopose.execution.command_queue import CommandQueue
from emopose.execution.gesture_command import Event, GestureCommand, State
from emopose.execution.posture import PostureLayer, PostureSettings
from emopose.execution.stroke_watch import StrokeWatch
from emopose.execution.trajectory import Trajectory, TrajectoryBuilder

SafetyCheck = Callable[[np.ndarray], "str | None"]


class Sequencer(CommandQueue):
    def __init__(self, builder: TrajectoryBuilder, neutral: np.ndarray, safety: SafetyCheck | None = None,
                 blend_s: float = 0.3, hold_s: float = 2.0, recover_s: float = 1.0,
                 interrupt_blend_s: float = 0.3, neutral_tolerance: float = 0.02,
                 preempt_after_s: float | None = None, stall_stop_late_s: float = 0.5,
                 on_event: Callable[[Event], None] | None = None, keep_events: int = 10_000,
                 posture: PostureSettings | None = None) -> None:
        super().__init__(on_event, keep_events)
        self.builder = builder
        self.neutral = np.asarray(neutral, dtype=float)
        self.posture = PostureLayer(posture, self.neutral, builder.limits, builder.dt)  # None: rest, still
        self.safety = safety
        self.blend_s, self.hold_s, self.recover_s = blend_s, hold_s, recover_s
        self.interrupt_blend_s, self.neutral_tolerance = interrupt_blend_s, neutral_tolerance
        self.preempt_after_s, self.stall_stop_late_s = preempt_after_s, stall_stop_late_s
        self.stroke_watch = StrokeWatch()  # measuring once a control loop's backend measures its joints
        self.construction_s: BoundedLog[float] = BoundedLog(keep_events)
        self.reset(self.neutral, 0.0)

    # -- public, thread-safe -------------------------------------------------------------------
    def reset(self, q0: np.ndarray, now: float) -> None:
        with self._lock:
            self.last = np.array(q0, dtype=float)
            self.state = State.IDLE
            self._queue.clear()
            self._motion: Trajectory | None = None
            self._index, self._motion_t0 = 0, now
            self._active: GestureCommand | None = None
            self._after_blend: GestureCommand | None = None
            self._stroke_tick = -1
            self._hold_since = now
            self.stroke_watch.clear()
            self.posture.reset()

    def interrupt(self, commands: list[GestureCommand] | tuple = (), now: float | None = None) -> None:
        """Clear pending actions; blend from the latest published pose to the first new command (or neutral).
        A timeline is queued whole: the arm heads for rest until its first gesture prepares from there."""
        with self._lock:
            now = self._hold_since if now is None else now
            if self._active is not None:
                self._emit(now, EventKind.STOPPED, self._active)
            self._queue.clear()
            timed = bool(commands) and commands[0].timed
            self._queue.extend(commands if timed else commands[1:])
            if commands and not timed:
                first = commands[0]
                self._start_blend(now, np.asarray(first.keyframes[0]), self.interrupt_blend_s, first)
            else:
                self._start_blend(now, self._home(now), self.recover_s, None)

    @property
    def active(self) -> GestureCommand | None:
        return self._active

    def settled(self) -> bool:
        """Nothing running and nothing queued (HOLDING or IDLE)."""
        with self._lock:
            return self.state in (State.IDLE, State.HOLDING) and not self._queue

    # -- the tick ------------------------------------------------------------------------------
    def step(self, now: float) -> np.ndarray:
        with self._lock:
            if self.state in (State.EXECUTING, State.BLENDING):
                self._advance(now)
            if self.state == State.EXECUTING and self._timed_head_due(now):
                self._emit(now, EventKind.CUT, self._active, "preempted at the next gesture's timeline start")
                self._active = None
                self._begin_or_hold(self._queue.popleft(), now)
            if self.state == State.EXECUTING and self._overdue(now):
                self._emit(now, EventKind.STOPPED, self._active, "preempted by an overdue successor")
                head = self._queue.popleft()
                self._start_blend(now, np.asarray(head.keyframes[0]), self.blend_s, head)
            if self.state in (State.IDLE, State.HOLDING) or self._recovering():
                self._maybe_start(now)
            if self.state == State.HOLDING and now - self._hold_since >= self.hold_s:
                self._recover(now)
            self._follow_posture(now)
            return self.last.copy()

    def observe(self, now: float, measured: np.ndarray) -> None:
        """A measured arm pose at `now`: emits the STROKE events it completes (see StrokeWatch)."""
        with self._lock:
            for stroke in self.stroke_watch.observe(now, measured):
                self._emit(now, EventKind.STROKE, stroke.command, stroke.detail)

    # -- internals (lock held) -----------------------------------------------------------------
    def _advance(self, now: float) -> None:
        due = round((now - self._motion_t0) / self.builder.dt)  # the sample this tick stands for
        if self.state == State.EXECUTING and due > self._index + 1 and not self._catch_up(now, due):
            return
        self._index += 1
        self.last = self._motion.samples[self._index].copy()
        if self._index == self._stroke_tick and self.state == State.EXECUTING:
            self._stroke_commanded(now)
        if self._index < len(self._motion.samples) - 1:
            return
        if self.state == State.EXECUTING:
            done, self._active = self._active, None
            self._emit(now, *((EventKind.CUT, done, "co-articulated into the next gesture") if done.cut
                              else (EventKind.COMPLETED, done)))
            head = self._queue[0] if self._queue else None
            if head is not None and head.release_at <= now:
                self._queue.popleft()
                if head.timed:
                    self._begin_or_hold(head, now)
                else:
                    self._start_blend(now, np.asarray(head.keyframes[0]), self.blend_s, head)
            else:
                self._set_state(now, State.HOLDING)
        elif self._after_blend is not None:
            command, self._after_blend = self._after_blend, None
            self._begin_or_hold(command, now)
        else:
            self._set_state(now, State.IDLE)

    def _catch_up(self, now: float, due: int) -> bool:
        """Re-time the running gesture after a stall; False: stopped (stroke > stall_stop_late_s late)."""
        motion, dt = self.builder.catch_up(self._motion, self._index, due - 1), self.builder.dt
        ahead = self._stroke_tick > self._index  # else reported already, or none
        stroke_tick = motion.arrival_tick(self._active.keyframes, self._active.stroke[0]) if ahead else -1
        late = (stroke_tick + due - 1 - self._stroke_tick) * dt
        if ahead and late > self.stall_stop_late_s:
            self._emit(now, EventKind.STOPPED, self._active, f"stall: stroke {late * 1e3:.0f} ms late")
            self._start_blend(now, self._home(now), self.recover_s, None)
            return False
        self._motion, self._index, self._motion_t0, self._stroke_tick = motion, 0, now - dt, stroke_tick
        return True

    def _stroke_commanded(self, now: float) -> None:
        if self.stroke_watch.measuring:
            self.stroke_watch.expect(self._active, now)
        self._emit(now, EventKind.STROKE_COMMANDED if self.stroke_watch.measuring else EventKind.STROKE,
                   self._active)

    def _timed_head_due(self, now: float) -> bool:
        return bool(self._queue) and self._queue[0].timed and self._queue[0].release_at <= now

    def _overdue(self, now: float) -> bool:
        return (self.preempt_after_s is not None and bool(self._queue)
                and now - self._queue[0].release_at >= self.preempt_after_s)

    def _recovering(self) -> bool:
        return self.state == State.BLENDING and self._after_blend is None and self._active is None

    def _maybe_start(self, now: float) -> None:
        while self._queue and self._queue[0].release_at <= now:
            if self._begin(self._queue.popleft(), now):
                return

    def _begin(self, command: GestureCommand, now: float) -> bool:
        started = time.perf_counter()
        keyframes = self.posture.retarget(command, self._home(now))
        if command.timed:
            times = np.asarray(command.offsets[1:]) + (command.release_at - now)
            motion = self.builder.build_timed(keyframes, times, self.last, command.blend_in)
        else:
            motion = self.builder.build(keyframes, command.duration, self.last, command.authored_times)
        self.construction_s.append(time.perf_counter() - started)
        reason = self.safety(motion.samples) if self.safety else None
        if reason is not None:
            self._emit(now, EventKind.REJECTED, command, reason)
            return False
        self._motion, self._index, self._motion_t0, self._active = motion, 0, now, command
        stroke = command.stroke
        self._stroke_tick = -1 if stroke is None else motion.arrival_tick(command.keyframes, stroke[0])
        self._set_state(now, State.EXECUTING)
        detail = (f"late={motion.late_s * 1e3:.0f}ms" if motion.late_s > 0.01
                  else f"stretch={motion.stretch:.2f}" if motion.stretch > 1 else "")
        self._emit(now, EventKind.STARTED, command, detail)
        return True

    def _begin_or_hold(self, command: GestureCommand, now: float) -> None:
        if not self._begin(command, now):
            self._set_state(now, State.HOLDING)

    def _start_blend(self, now: float, target: np.ndarray, duration: float,
                     then: GestureCommand | None) -> None:
        self._motion = self.builder.blend(self.last, target, duration)
        self._index, self._motion_t0, self._active, self._after_blend = 0, now, None, then
        self._set_state(now, State.BLENDING)

    def _recover(self, now: float) -> None:
        home = self._home(now)
        if np.max(np.abs(self.posture.held(self.last) - home)) <= self.neutral_tolerance:
            self._set_state(now, State.IDLE)
        else:
            self._start_blend(now, home, self.recover_s, None)

    def _home(self, now: float) -> np.ndarray:
        """Between gestures the arms go to the current posture (a POSTURE event records a change)."""
        if self.posture.stale:
            self._emit(now, EventKind.POSTURE, None, self.posture.current)
        return self.posture.home()

    def _follow_posture(self, now: float) -> None:
        """A changed posture is blended to once nothing runs or waits; the idle motion moves a settled arm."""
        settled = self.state in (State.IDLE, State.HOLDING) and not self._queue
        if self.posture.stale and (settled or self._recovering()):
            self._start_blend(now, self._home(now), self.posture.settings.transition_s, None)
            settled = False
        self.last = self.posture.idle(self.last, now, settled)

    def _set_state(self, now: float, state: State) -> None:
        if state == State.HOLDING:
            self._hold_since = now
        if state != self.state:
            self.state = state
            self._emit(now, EventKind.STATE, None, state.value)
