"""Runs `shadowbake bake` as a child process and follows it through its stderr: the
`--progress-lines` lines (`progress F`, F from 0 to 1; docs/cli.md), its warnings and its one-line
error (`shadowbake: error: <file>:<line>: <item>: <problem>`, docs/cli.md, "Exit codes").

A thread reads the pipe, so that Blender's interface (a modal operator's timer) only polls."""

import os
import queue
import re
import shutil
import signal
import subprocess
import threading

_ITEM = re.compile(r"\b(object|light) '([^']*)'")


def find_executable(configured):
    """The shadowbake executable: the add-on preference when set, else `shadowbake` on PATH."""
    if configured:
        import bpy
        path = bpy.path.abspath(configured)
        return path if os.path.isfile(path) and os.access(path, os.X_OK) else None
    return shutil.which("shadowbake")


def command(executable, scene_file, out_dir, preset):
    cmd = [executable, "bake", scene_file, "-o", out_dir, "--progress-lines"]
    if preset != "final":
        cmd += ["--preset", preset]
    return cmd


def in_blender_words(message, names):
    """A shadowbake message with its items named as Blender names them: `object 'Chair_seat'`
    becomes `object "Chair seat"`."""
    def blender(match):
        return f'{match.group(1)} "{names.blender(match.group(2))}"'
    text = message
    for prefix in ("shadowbake: error: ", "shadowbake: warning: "):
        if text.startswith(prefix):
            text = text[len(prefix):]
    return _ITEM.sub(blender, text)


class BakeProcess:
    """One running bake. `poll()` returns the newest progress fraction; `returncode` is set once
    it ended; `errors` and `warnings` hold its error and warning lines."""

    def __init__(self, cmd):
        self.cmd = cmd
        self.progress = 0.0
        self.errors, self.warnings, self.other = [], [], []
        self.returncode = None
        self._lines = queue.Queue()
        self._process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                         stdin=subprocess.DEVNULL, text=True, encoding="utf-8",
                                         errors="replace")
        self._stdout = []
        self._threads = [threading.Thread(target=self._read, args=(self._process.stderr, True),
                                          daemon=True),
                         threading.Thread(target=self._read, args=(self._process.stdout, False),
                                          daemon=True)]
        for t in self._threads:
            t.start()

    def _read(self, pipe, is_stderr):
        for line in pipe:
            if is_stderr:
                self._lines.put(line.rstrip("\n"))
            else:
                self._stdout.append(line.rstrip("\n"))
        pipe.close()

    def poll(self):
        while True:
            try:
                line = self._lines.get_nowait()
            except queue.Empty:
                break
            if line.startswith("progress "):
                try:
                    self.progress = float(line.split()[1])
                except (IndexError, ValueError):
                    self.other.append(line)
            elif line.startswith("shadowbake: error: "):
                self.errors.append(line)
            elif line.startswith("shadowbake: warning: "):
                self.warnings.append(line)
            elif line:
                self.other.append(line)
        if self.returncode is None:
            code = self._process.poll()
            if code is not None:
                for t in self._threads:
                    t.join()
                self.returncode = code
                self.poll()
        return self.progress

    def wait(self, on_progress=None):
        """Blocks until the bake ends (background mode); `on_progress(f)` at each new fraction."""
        last = -1.0
        while self.returncode is None:
            try:
                self._process.wait(timeout=0.1)
            except subprocess.TimeoutExpired:
                pass
            fraction = self.poll()
            if on_progress and fraction != last:
                on_progress(fraction)
                last = fraction
        return self.returncode

    def cancel(self):
        """Asks the bake to stop as Ctrl-C does (SIGINT; terminate where there is no SIGINT):
        shadowbake then removes its staging folder and publishes nothing, so the folder keeps
        the earlier bake (docs/cli.md, "Outputs are all or nothing")."""
        if self._process.poll() is None:
            if hasattr(signal, "SIGINT") and os.name == "posix":
                self._process.send_signal(signal.SIGINT)
            else:
                self._process.terminate()
        try:
            self._process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self._process.kill()
        self.wait()

    @property
    def summary(self):
        return self._stdout

    def failure(self, names):
        """The bake's error in Blender's words, or a description of how it ended."""
        if self.errors:
            return in_blender_words(self.errors[-1], names)
        if self.returncode in (-signal.SIGINT, 130):
            return "cancelled"
        tail = "; ".join(self.other[-3:])
        return f"shadowbake ended with exit code {self.returncode}" + (f": {tail}" if tail else "")
