"""What a stream solver's contact records need from the whole run: each ball's contacts
numbered in time order (``index``) and, for plate contacts, the height of the free flight's
apex that follows (``next_apex_height``)."""

import math

import numpy as np

from tailbeam.results.records import PLATE, End


def number_contacts(contacts, leaves, incline) -> None:
    """Fill ``index`` (1, 2, ... per ball in time order) and ``next_apex_height`` of a stream
    solver's ``Impact`` records (``contacts``), which need the whole run: the ball's later
    contacts and its ``LeaveEvent`` (``leaves``) on ``incline``. Idempotent."""
    leave = {e.ball: e.time for e in leaves}
    starts = _starts_by_ball(contacts)
    g_n = incline.gravity * math.cos(math.radians(incline.inclination))
    count: dict = {}
    for rec in sorted(contacts, key=lambda r: (r.t_start, r.ball)):
        count[rec.ball] = count.get(rec.ball, 0) + 1
        rec.index = count[rec.ball]
        rec.next_apex_height = _next_apex(rec, g_n, starts.get(rec.ball), leave.get(rec.ball))


def _starts_by_ball(contacts) -> dict:
    out: dict = {}
    for rec in contacts:
        out.setdefault(rec.ball, []).append(rec.t_start)
    return {k: np.sort(v) for k, v in out.items()}


def _next_apex(rec, g_n, starts, t_leave) -> float:
    """v_out^2 / (2 g_n) for a plate contact whose ball then flies freely to its apex."""
    if rec.partner != PLATE or rec.end != End.SEPARATED or g_n <= 0.0 or rec.v_out < 0.0:
        return math.nan
    t_apex = rec.t_end + rec.v_out / g_n
    later = starts[starts > rec.t_start]
    if later.size and later[0] <= t_apex:
        return math.nan  # it touched the plate or a ball before the apex
    if t_leave is not None and t_leave <= t_apex:
        return math.nan
    return rec.v_out**2 / (2.0 * g_n)
