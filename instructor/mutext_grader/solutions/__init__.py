"""Reference solutions of the exercises (one module per exercise).

Each module is itself a valid submission: ``mutext grade EXERCISE`` on it
scores full marks, and it uses only what students may use (numpy, scipy,
control, :mod:`mutext.lti`, :mod:`mutext.hinf`).
"""
