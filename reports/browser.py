"""Headless Chromium helpers: load a report as a browser would, or take a screenshot.

Every call starts a fresh Chromium with a new temporary profile (``--user-data-dir``), is
bounded by a timeout (60 s by default) after which Chromium's whole process group is killed,
and raises :class:`RuntimeError` naming the cause when Chromium is missing, fails or hangs.
Debian's package is ``chromium`` (``apt-get install chromium``).
"""
from __future__ import annotations

import os
import shutil
import signal
import subprocess
import tempfile
from pathlib import Path

__all__ = ["CHROMIUM_NAMES", "DEFAULT_TIMEOUT_S", "find_chromium", "chromium_args",
           "dump_dom", "screenshot"]

CHROMIUM_NAMES: tuple[str, ...] = ("chromium", "chromium-browser", "google-chrome")
"""Executables looked for on PATH, in this order."""
_FALLBACK_PATHS: tuple[str, ...] = ("/usr/bin/chromium",)
DEFAULT_TIMEOUT_S: float = 60.0
"""How long one Chromium run may take."""
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_STDERR_NOISE = ("dbus", "unexpected operator", "Fontconfig", "sandbox", "gcm", "GCM")


def find_chromium() -> str | None:
    """The path of a Chromium (or Chrome) executable, or None if there is none.

    Looks for ``chromium``, ``chromium-browser`` and ``google-chrome`` on PATH, then for
    ``/usr/bin/chromium``.
    """
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    for path in _FALLBACK_PATHS:
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    return None


def chromium_args(user_data_dir: str | Path) -> list[str]:
    """The flags every headless run uses, with its own profile folder.

    Parameters
    ----------
    user_data_dir : str or Path
        A fresh, empty folder for Chromium's profile.

    Returns
    -------
    list of str
    """
    return ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
            "--disable-background-networking", "--disable-component-update",
            "--disable-sync", f"--user-data-dir={user_data_dir}"]


def _require_chromium(chromium: str | None) -> str:
    exe = chromium or find_chromium()
    if exe is None:
        raise RuntimeError("headless Chromium not found (looked for "
                           f"{', '.join(CHROMIUM_NAMES)} on PATH and "
                           f"{', '.join(_FALLBACK_PATHS)}); install Debian's package: "
                           "apt-get install chromium")
    return exe


def _file_url(html_path: str | Path) -> str:
    path = Path(html_path).resolve()
    if not path.is_file():
        raise FileNotFoundError(f"no such HTML file: {path}")
    return path.as_uri()


def _stderr_tail(stderr: bytes, lines: int = 6) -> str:
    """The last meaningful lines of Chromium's stderr (its D-Bus chatter left out)."""
    text = stderr.decode("utf-8", "replace").splitlines()
    useful = [line for line in text if line.strip()
              and not any(noise in line for noise in _STDERR_NOISE)]
    tail = (useful or text)[-lines:]
    return " | ".join(line.strip() for line in tail) or "(no output on stderr)"


def _run(argv: list[str], timeout: float, what: str) -> bytes:
    """Run Chromium in its own process group; kill the whole group on timeout."""
    try:
        proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, start_new_session=True)
    except OSError as exc:
        raise RuntimeError(f"could not start Chromium ({argv[0]}): {exc}") from exc
    try:
        stdout, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        try:
            proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            pass
        raise RuntimeError(f"headless Chromium took longer than {timeout:g} s to {what}; "
                           "killed it") from None
    except BaseException:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()
        raise
    if proc.returncode != 0:
        raise RuntimeError(f"headless Chromium failed to {what} (exit status "
                           f"{proc.returncode}): {_stderr_tail(stderr)}")
    return stdout


def dump_dom(html_path: str | Path, *, timeout: float = DEFAULT_TIMEOUT_S,
             chromium: str | None = None, window: tuple[int, int] | None = None) -> str:
    """Load a local HTML file in headless Chromium and return the DOM after scripts ran.

    Parameters
    ----------
    html_path : str or Path
    timeout : float, optional
        Seconds before Chromium is killed (default 60).
    chromium : str, optional
        The executable; found with :func:`find_chromium` when not given.
    window : (int, int), optional
        The window's width and height in CSS pixels (Chromium's default when not given), for
        checks of the layout at a given screen size.

    Returns
    -------
    str
        The serialised document (``--dump-dom``), taken after the page's load event.

    Raises
    ------
    FileNotFoundError
        If the HTML file does not exist.
    RuntimeError
        If Chromium is missing, fails, prints nothing or takes longer than ``timeout``.
    """
    url = _file_url(html_path)
    exe = _require_chromium(chromium)
    with tempfile.TemporaryDirectory(prefix="sidbench-chromium-",
                                     ignore_cleanup_errors=True) as profile:
        size = [f"--window-size={int(window[0])},{int(window[1])}"] if window else []
        argv = [exe, *chromium_args(profile), *size, "--dump-dom", url]
        out = _run(argv, timeout, f"load {html_path}")
    text = out.decode("utf-8", "replace")
    if not text.strip():
        raise RuntimeError(f"headless Chromium printed no DOM for {html_path}")
    return text


def screenshot(html_path: str | Path, png_path: str | Path, width: int = 1280,
               height: int = 2000, *, timeout: float = DEFAULT_TIMEOUT_S,
               chromium: str | None = None) -> Path:
    """Render a local HTML file to a PNG of ``width`` x ``height`` CSS pixels.

    The PNG is written beside ``png_path`` under a temporary name and renamed into place,
    so a failed run leaves no partial file.

    Parameters
    ----------
    html_path : str or Path
    png_path : str or Path
        The PNG to write; its folder is created if needed.
    width, height : int, optional
        The window size (default 1280 x 2000); the page is cut at the bottom.
    timeout : float, optional
        Seconds before Chromium is killed (default 60).
    chromium : str, optional
        The executable; found with :func:`find_chromium` when not given.

    Returns
    -------
    Path
        ``png_path``.

    Raises
    ------
    ValueError
        If the size is not positive.
    FileNotFoundError
        If the HTML file does not exist.
    RuntimeError
        If Chromium is missing, fails, writes no PNG or takes longer than ``timeout``.
    """
    if int(width) <= 0 or int(height) <= 0:
        raise ValueError(f"screenshot size must be positive; got {width} x {height}")
    url = _file_url(html_path)
    exe = _require_chromium(chromium)
    target = Path(png_path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.",
                                    suffix=".png")
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        tmp.unlink()  # Chromium creates the file itself; an empty one would hide a failure
        with tempfile.TemporaryDirectory(prefix="sidbench-chromium-",
                                         ignore_cleanup_errors=True) as profile:
            argv = [exe, *chromium_args(profile), f"--screenshot={tmp}",
                    f"--window-size={int(width)},{int(height)}", "--hide-scrollbars", url]
            _run(argv, timeout, f"screenshot {html_path}")
        if not tmp.is_file() or tmp.read_bytes()[:8] != _PNG_SIGNATURE:
            raise RuntimeError(f"headless Chromium wrote no PNG for {html_path}")
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)
    return target
