"""A skybake call run off Blender's main thread, and the modal operator
steps that drive it.

A long skybake call (a bake, a sky panorama) blocks Blender if it runs in
execute(). From the UI, the operators run it in a thread instead: a timer
polls its progress into the status bar and the window manager's progress
cursor, and Esc cancels it through the call's progress callback. Blender's
data is touched on the main thread only, before the call and after it. One
job runs at a time (`running`); unregistering the add-on cancels it.
"""

import threading
import time

running = None  # the Job of a modal operator in flight


class Cancelled(Exception):
    """Raised by the progress callback to stop the call (Esc)."""


class Job:
    """call(progress) in a thread; a flag stops it at its next progress event."""

    def __init__(self, call):
        self.call = call
        self.fraction = 0.0
        self.cancel_requested = False
        self.cancelled = False
        self.result = None
        self.error = None
        self.done = threading.Event()
        self.thread = None
        self.wall_seconds = 0.0

    def _progress(self, event):  # a skybake worker thread, holding the GIL: no bpy here
        self.fraction = event.fraction
        if self.cancel_requested:
            raise Cancelled()

    def run(self):
        start = time.perf_counter()
        try:
            self.result = self.call(self._progress)
        except (Cancelled, KeyboardInterrupt):
            self.cancelled = True
        except Exception as e:  # skybake.Error and anything unexpected: reported, never raised in Blender
            self.error = e
        finally:
            self.wall_seconds = time.perf_counter() - start
            self.done.set()

    def start(self):
        self.thread = threading.Thread(target=self.run, name="skybake", daemon=True)
        self.thread.start()

    def cancel(self, wait_seconds=None):
        self.cancel_requested = True
        if self.thread is not None and wait_seconds is not None:
            self.thread.join(wait_seconds)


def cancel_running():
    global running
    if running is not None:
        running.cancel(wait_seconds=30.0)
        running = None


def error_text(e):
    return getattr(e, "message", None) or str(e) or type(e).__name__


class ModalJob:
    """Mixin for an operator whose invoke() runs a Job in a thread.

    The operator sets self._job and calls _start_modal(); when the job is done,
    modal() calls self._done(context) on the main thread. _describe() words the
    status bar's text while it runs.
    """

    _timer = None

    def _start_modal(self, context, job):
        global running
        self._job = job
        running = job
        job.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        self._status(context)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _status(self, context):
        job = self._job
        text = "skybake: cancelling..." if job.cancel_requested else (
            f"skybake: {self._describe()} {100.0 * job.fraction:.0f}%, Esc to cancel")
        if context.workspace is not None:
            context.workspace.status_text_set(text)
        context.window_manager.progress_update(int(100.0 * job.fraction))

    def _end(self, context):
        global running
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        running = None

    def modal(self, context, event):
        if event.type == "ESC" and event.value == "PRESS":
            self._job.cancel()
            self._status(context)
            return {"RUNNING_MODAL"}
        if event.type == "TIMER":
            if self._job.done.is_set():
                self._job.thread.join()
                self._end(context)
                return self._done(context)
            self._status(context)
        return {"PASS_THROUGH"}

    def cancel(self, context):  # Blender closes the window or reloads the file mid-call
        self._job.cancel(wait_seconds=30.0)
        self._end(context)
