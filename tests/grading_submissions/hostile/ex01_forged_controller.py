"""Hostile: forge a 1500-state controller on the results channel for (d).

Checking a closed loop of that size took the grader's process 11 minutes, outside any time limit;
the grader must reject the value by its size before computing anything (and the forged line is
long: 1500 x 1500 zeros)."""
import gc
import json
import os


def _channel():
    for o in gc.get_objects():
        if isinstance(o, dict) and "nonce" in o and "results_fd" in o:
            return o["nonce"], o["results_fd"]
    raise RuntimeError("no channel")


def controller():
    nonce, fd = _channel()
    n = 1500
    zero_row = [0] * n
    value = {"A": [[-1 if i == j else 0 for j in range(n)] for i in range(n)], "B": [[0]] * n,
             "C": [zero_row], "D": [[0]], "dt": None, "inputs": ["y"], "outputs": ["u"]}
    os.write(fd, (json.dumps({"event": "result", "phase": "d", "nonce": nonce,
                              "calls": [{"ok": True, "value": value}]}) + "\n").encode())
    raise RuntimeError("the forged controller was sent")
