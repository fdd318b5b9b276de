"""Drive the robot from the notebook: a keyboard pad that publishes geometry_msgs/Twist on /cmd_vel
while a key is held, with teleop_twist_keyboard's keys (:mod:`course_lib.robot.teleop_keyboard`).

    pad = teleop_widget.KeyboardTeleop()   # click it, then hold i (forward), j/l (turn), ...
    pad                                     # the cell's value shows it

Press-and-hold: while a moving key (or an arrow key) is held the kernel publishes the Twist at
``rate`` Hz (10) from the session's background thread; on release, when the pad loses focus, or
when the browser stops reporting the key (a closed tab: no heartbeat for ``deadman`` s) it
publishes one zero Twist and stops publishing. q/z, w/x and e/c change the speeds by 10 %, as in
the terminal tool. The page's part is a small ES module in this file (anywidget): nothing is
fetched from elsewhere.

In plain ROS 2: ``ros2 run teleop_twist_keyboard teleop_twist_keyboard`` in a terminal.
"""

from __future__ import annotations

import time

import anywidget
import traitlets

from course_lib.robot.teleop_keyboard import MOVE_BINDINGS, SPEED_BINDINGS, Teleop, apply_key, twist_message

_ESM = """
const ARROWS = {ArrowUp: "i", ArrowDown: ",", ArrowLeft: "j", ArrowRight: "l"};
function render({ model, el }) {
  const pad = document.createElement("div");
  pad.tabIndex = 0;
  pad.className = "course-teleop";
  pad.style.cssText = "display:inline-block;padding:8px 12px;border:2px solid #888;border-radius:6px;" +
    "font-family:monospace;white-space:pre;outline:none;cursor:pointer;user-select:none";
  const show = () => {
    const held = model.get("held");
    pad.textContent = "   u    i    o\\n   j    k    l\\n   m    ,    .\\n" +
      (document.activeElement === pad ? "driving: hold a key" + (held.length ? " [" + held.join("") + "]" : "")
                                      : "click here to drive") + "\\n" + model.get("status");
    pad.style.borderColor = document.activeElement === pad ? "#2a7" : "#888";
  };
  const held = new Set();
  let beat = null;
  const send = () => {
    model.set("held", [...held]);
    model.set("beat", model.get("beat") + 1);
    model.save_changes();
    show();
  };
  const release = () => {
    held.clear();
    if (beat !== null) { clearInterval(beat); beat = null; }
    send();
  };
  pad.addEventListener("keydown", (event) => {
    const key = ARROWS[event.key] || event.key;
    if (key.length !== 1) return;
    event.preventDefault();
    event.stopPropagation();  // JupyterLab's shortcuts (a, b, m, ...) must not see it
    if (!event.repeat) {
      if (model.get("speed_keys").includes(key)) { model.send({speed_key: key}); return; }
      held.add(key);
      send();
      if (beat === null) beat = setInterval(send, 100);
    }
  });
  pad.addEventListener("keyup", (event) => {
    const key = ARROWS[event.key] || event.key;
    if (!held.has(key)) return;
    held.delete(key);
    if (held.size === 0) release(); else send();
  });
  pad.addEventListener("blur", release);
  pad.addEventListener("focus", show);
  model.on("change:status", show);
  el.appendChild(pad);
  show();
  return () => { release(); };
}
export default { render };
"""


class KeyboardTeleop(anywidget.AnyWidget):
    """The keyboard pad (see the module's docstring)."""

    _esm = traitlets.Unicode(_ESM).tag(sync=True)
    # Not `keys`: ipywidgets' Widget.keys lists the synced traits, and a trait of that name empties the state
    held = traitlets.List(traitlets.Unicode()).tag(sync=True)
    beat = traitlets.Int(0).tag(sync=True)
    speed_keys = traitlets.List(traitlets.Unicode(), list(SPEED_BINDINGS)).tag(sync=True)
    status = traitlets.Unicode("").tag(sync=True)

    def __init__(self, topic: str = "/cmd_vel", rate: float = 10.0, deadman: float = 0.5, **kwargs):
        super().__init__(**kwargs)
        from geometry_msgs.msg import Twist
        from rclpy.node import Node

        from course_lib.ros import session

        self.state, self.deadman = Teleop(), deadman
        self.last_beat = 0.0
        self.moving = False
        session.start()
        self.node = session.add_node(Node("teleop_widget"))
        self.publisher = self.node.create_publisher(Twist, topic, 10)
        self.timer = self.node.create_timer(1.0 / rate, self.tick)
        self.observe(self.on_beat, names=["held", "beat"])
        self.on_msg(self.on_message)
        self.status = self.speeds()

    def speeds(self) -> str:
        return f"speed {self.state.speed:.2f} m/s, turn {self.state.turn:.2f} rad/s"

    def on_beat(self, _change) -> None:
        self.last_beat = time.monotonic()

    def on_message(self, _widget, content, _buffers) -> None:
        if isinstance(content, dict) and content.get("speed_key") in SPEED_BINDINGS:
            apply_key(self.state, content["speed_key"])
            self.status = self.speeds()

    def held_direction(self) -> tuple | None:
        """The Twist's values for the newest held moving key, or None when none is held (or heard of lately)."""
        moving = [key for key in self.held if key in MOVE_BINDINGS]
        if not moving or time.monotonic() - self.last_beat > self.deadman:
            return None
        apply_key(self.state, moving[-1])
        return self.state.twist()

    def tick(self) -> None:
        """The timer: publish while a key is held; one zero Twist when the last one is let go."""
        values = self.held_direction()
        if values is not None:
            self.publisher.publish(twist_message(values))
            self.moving = True
        elif self.moving:
            self.publisher.publish(twist_message((0.0, 0.0, 0.0, 0.0)))
            self.moving = False
