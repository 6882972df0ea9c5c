"""The node's /diagnostics status (once a second, wall time): the real-time factor against its target,
step and publish times, CPU, body and contact counts, rejections, and per topic the messages published,
the matched subscribers and the commands received, accepted, rejected and lost (docs/ros_interface.md)."""
from __future__ import annotations

import time

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

import collide

from collide_ros import qos
from collide_ros.diag_name import physics_status


class Diagnostics:
    """Owns ``_pub_diag``, the window the rates are measured over (``_diag_wall``, ``_diag_sim``,
    ``_diag_cpu``), ``last_rtf`` and ``last_cpu``."""

    def _init_diagnostics(self) -> None:
        self._pub_diag = self._publisher(DiagnosticArray, "/diagnostics", qos.DIAGNOSTICS)

    def _start_diagnostics_window(self) -> None:
        self._diag_wall = time.perf_counter()
        self._diag_sim = self.sim_time
        self._diag_cpu = time.process_time()
        self.last_rtf = 0.0
        self.last_cpu = 0.0

    def _publish_diagnostics(self) -> None:
        wall, cpu, sim = time.perf_counter(), time.process_time(), self.sim_time
        dw = max(wall - self._diag_wall, 1e-9)
        self.last_rtf = (sim - self._diag_sim) / dw
        self.last_cpu = (cpu - self._diag_cpu) / dw
        n = max(self._window_steps, 1)
        target = float(self._p["real_time_factor"])
        st = DiagnosticStatus()
        st.name = physics_status(self.get_fully_qualified_name())
        st.hardware_id = "libcollide " + collide.version()
        slow = target > 0 and not self._paused and self.last_rtf < 0.9 * target
        st.level = DiagnosticStatus.WARN if slow else DiagnosticStatus.OK
        st.message = ("paused" if self._paused else
                      f"real-time factor {self.last_rtf:.3f} (target {target:g})" + (" - falling behind" if slow else ""))
        if self.failing_since is not None:
            # the world state itself cannot be stepped (commands and springs are gone already):
            # only a reset, a parameter change or a new command can get it going again
            st.level = DiagnosticStatus.ERROR
            st.message = f"physics steps failing since t={self.failing_since:.6f} s: {self.last_rejection}"
        vals = {
            "real_time_factor": f"{self.last_rtf:.4f}", "target_real_time_factor": f"{target:g}",
            "step_time_mean_ms": f"{1e3 * self._step_time_sum / n:.4f}",
            "step_time_max_ms": f"{1e3 * self._step_time_max:.4f}",
            "publish_time_mean_ms": f"{1e3 * self._pub_time_sum / n:.4f}",
            "publish_thread_time_mean_ms": f"{1e3 * self._publish_thread_time() / n:.4f}",
            "steps_per_second": f"{self._window_steps / dw:.1f}", "late_steps": str(self.late_steps),
            "cpu_percent": f"{100 * self.last_cpu:.1f}", "bodies": str(len(self._names)),
            "dynamic_bodies": str(len(self._dyn_names)), "contacts": str(len(self.world.contacts)),
            "sim_time": f"{sim:.6f}", "paused": str(self._paused).lower(),
            "rejected_commands": str(self.rejected), "last_rejection": self.last_rejection,
            "dropped_contacts": str(self.dropped_contacts),
            "dropped_impacts": str(self.dropped_impacts), "split_steps": str(self.split_steps),
        }
        vals.update(self._count_values())
        st.values = [KeyValue(key=k, value=v) for k, v in vals.items()]
        msg = DiagnosticArray()
        sec, ns = self._stamp()
        msg.header.stamp = Time(sec=sec, nanosec=ns)
        msg.status = [st]
        self._pub_diag.publish(msg)
        self._diag_wall, self._diag_cpu, self._diag_sim = wall, cpu, sim
        self._step_time_sum = self._step_time_max = self._pub_time_sum = 0.0
        self._window_steps = 0

    def _count_values(self) -> dict[str, str]:
        """published/<topic> and subscribers/<topic> for every publisher (published/diagnostics: the
        ones before this message), then received/, accepted/, rejected/, lost/<topic> for every command topic (docs/ros_interface.md)."""
        vals = {f"published/{k}": str(p.count) for k, p in sorted(self._published.items())}
        # the writer's matched readers, not the graph's subscriptions: a subscription the graph
        # already shows may not be matched yet, and gets nothing published before it is
        vals.update({f"subscribers/{k}": str(p.pub.get_subscription_count())
                     for k, p in sorted(self._published.items())})
        for topic, c in sorted(self._commands.items()):
            vals[f"received/{topic}"] = str(c.received)
            vals[f"accepted/{topic}"] = str(c.accepted)
            vals[f"rejected/{topic}"] = str(c.rejected)
            vals[f"lost/{topic}"] = str(c.lost)
        return vals
