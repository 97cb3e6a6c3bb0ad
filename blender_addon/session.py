# SPDX-License-Identifier: MIT
"""Everything the add-on remembers between Blender's events, in one object: `current`.

register() begins a session and unregister() ends it (__init__.py), so an add-on disabled and
enabled again starts clean: no frame, helper request or kept layers of before. The other modules
keep constants only; what changes lives here, each field named for what it holds, with the
module that uses it. State that another thread touches sits beside its lock."""
import contextlib
import threading

from . import main_thread


class Session:
    def __init__(self):
        # The add-on's preferences (preferences.py copies them here).
        self.export_dir = ""  # "Keep passes in", made absolute; empty: compute.PROCESS_EXPORT_DIR
        self.use_helper_process = True  # "Helper render in its own process"
        # Why libssao's parameter table could not be read when the node registered (node.py).
        self.library_error = None

        # A render's events (handlers.py).
        self.render_started = 0.0  # time.time() of the last render's start: older exports stale
        self.pending_frames = []   # UI: (scene name, frame) rendered, waiting for the timer
        self.written_frames = []   # UI: (scene name, frame, output file, passes file), Ctrl+F12
        self.recomposited = {}     # headless: (scene name, frame) -> (passes file, AO layers)
        self.sequences = None      # headless: the render job's compute.Sequences (init to end)
        self.shot_starts = {}      # scene name -> frame_start as the file was loaded (warm_up.py)
        self.record_to = None      # warm_up.py's child: where its Sequences record the frames
        self.movie_warned = set()  # scenes told once that a movie cannot be written again
        self.run_with_writes = None  # what the window manager property's update runs
        self.nudge_scene = None    # the scene whose UI compositor is nudged until it runs
        self.nudge_tries = 0
        self.nudge_composited = False  # a composite started since the last nudge
        # Render-thread work waiting for the main thread (main_thread.py).
        self.main_thread = main_thread.Handover()

        # Re-entrancy: the add-on's own work fires Blender's handlers and update callbacks,
        # which must then do nothing (set with doing()).
        self.rendering_layers = False   # hidden_surfaces.py's helper render
        self.recompositing = False      # recomposite.py's render of the compositor
        self.copying_helper = False     # recomposite.py copying a scene: its nodes share AO
        self.restoring_settings = False  # saved_form.py putting a saved node's settings back

        # Hidden-surface layers (hidden_surfaces.py): scene name -> {layers key: layers}.
        self.kept_layers = {}
        # Helper processes (helper_process.py). The render thread cancels them (render_pre in
        # the UI): `helper_lock` guards the three tables.
        self.helper_lock = threading.Lock()
        self.helper_requests = {}  # (scene name, requester) -> helper_process._Request
        self.helper_renders = {}   # (scene name, layers key) -> helper_process._Render
        self.helper_failed = {}    # (scene name, layers key) -> error, until it renders again
        self.helpers_started = 0   # helper processes started (tests count them)

    _FLAGS = ("rendering_layers", "recompositing", "copying_helper", "restoring_settings")

    @contextlib.contextmanager
    def doing(self, flag):
        """Sets the re-entrancy flag `flag` (one of _FLAGS) while the block runs."""
        if flag not in self._FLAGS:
            raise ValueError(f"no re-entrancy flag {flag!r}")
        setattr(self, flag, True)
        try:
            yield
        finally:
            setattr(self, flag, False)

    def helper_rendering(self):
        """The add-on's own renders (re-composite, hidden surfaces) fire the handlers too."""
        return self.rendering_layers or self.recompositing

    def helpers_busy(self):
        """Helper renders asked for or running (helper_process.poll() has work)."""
        return bool(self.helper_requests or self.helper_renders)

    def busy(self):
        """Work left for the main-thread timer: rendered frames to finish, helper renders."""
        return bool(self.pending_frames or self.written_frames) or self.helpers_busy()


current = Session()


def begin():
    """register(): a new session."""
    global current
    current = Session()
    return current


def end():
    """unregister(), after the modules let go of their work: what the session held is dropped."""
    begin()
