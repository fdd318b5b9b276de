"""course_lib.ros.type_support_lock: a second thread's type check waits for the first one's whole
import of the type support, as the generated code needs (it sets _TYPE_SUPPORT before the inner types)."""

import threading

import rclpy.action.client
import rclpy.type_support

from course_lib.ros import type_support_lock


def half_imported_type(started: threading.Event, go_on: threading.Event):
    """A type whose support import sets _TYPE_SUPPORT, then waits for `go_on`, then readies its inner type."""

    class Metaclass(type):
        _TYPE_SUPPORT = None
        inner_ready = False

        @classmethod
        def __import_type_support__(cls):
            cls._TYPE_SUPPORT = object()
            started.set()
            assert go_on.wait(10)
            cls.inner_ready = True

    return Metaclass("Half", (), {})()


def test_a_second_check_waits_for_the_first_ones_whole_import():
    type_support_lock.install()
    check = rclpy.action.client.check_for_type_support  # the name the action client took
    assert check is rclpy.type_support.check_for_type_support and check.holds_the_lock
    started, go_on = threading.Event(), threading.Event()
    instance = half_imported_type(started, go_on)
    first = threading.Thread(target=check, args=(instance,))
    first.start()
    assert started.wait(10)
    seen = []
    second = threading.Thread(target=lambda: (check(instance), seen.append(type(instance).inner_ready)))
    second.start()
    second.join(0.3)
    assert second.is_alive() and seen == [], "the second check went on while the first was importing"
    go_on.set()
    first.join(10)
    second.join(10)
    assert seen == [True]


def test_install_twice_wraps_once():
    type_support_lock.install()
    once = rclpy.type_support.check_for_type_support
    type_support_lock.install()
    assert rclpy.type_support.check_for_type_support is once
