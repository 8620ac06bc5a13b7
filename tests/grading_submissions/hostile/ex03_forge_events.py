"""Hostile: forge results-channel events (found with gc) to reset the time limit while looping."""
import gc
import json
import os
import time


def _channel():
    for o in gc.get_objects():
        if isinstance(o, dict) and "nonce" in o and "results_fd" in o:
            return o["nonce"], o["results_fd"]
    raise RuntimeError("no channel")


def natural_frequency(t, y, cycles):
    nonce, fd = _channel()
    while True:
        for ev in ({"event": "start", "phase": "a1"}, {"event": "boot"}, {"event": "start", "phase": "a2"},
                   {"event": "confined", "applied": ["uid 0"], "readable": [], "writable": []}):
            os.write(fd, (json.dumps(dict(ev, nonce=nonce)) + "\n").encode())
        time.sleep(0.2)


def damping_ratio(t, y, cycles):
    # a forged result for the next question, with a value of the wrong kind: must be rejected
    nonce, fd = _channel()
    os.write(fd, (json.dumps({"event": "result", "phase": "a2", "nonce": nonce,
                              "calls": [{"ok": True, "value": {"__reduce__": "os.system"}}] * 3}) + "\n").encode())
    return 0.0
