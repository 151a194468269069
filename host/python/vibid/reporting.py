"""The HTML rig report (``vibid report``)."""
from __future__ import annotations

from typing import Optional, Sequence

from . import _vibid

def report(output: str, identify: Optional[str] = None, truth: Optional[str] = None,
           dob: Optional[str] = None, measured: str = "", estimates: Sequence[str] = (),
           skip_s: float = 0.0, notes: Sequence[str] = (), title: str = "vibid rig report",
           accept_flagged: bool = False) -> None:
    """Writes the HTML report (``vibid report``, same options): from the directory
    ``vibid identify --report`` (or ``Identification``'s run) wrote, optionally against the rig's
    true model file, and from an observer recording (``dob``, its ``measured`` force column and
    the ``estimates`` COLUMN[=LABEL], ``skip_s`` seconds left out at each end). A flagged
    identification raises vibid.FlaggedResultError unless ``accept_flagged=True`` (then its
    verdict is red at the top of the page)."""
    r = _vibid._ReportRequest()
    r.title, r.identify_dir, r.truth = title, str(identify or ""), str(truth or "")
    r.dob_recording, r.measured, r.estimates = str(dob or ""), measured, list(estimates)
    r.skip_s, r.notes = skip_s, list(notes)
    r.accept_flagged = bool(accept_flagged)
    _vibid.report(r, str(output))
