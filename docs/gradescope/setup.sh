#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder image.
# It installs mutext where the unprivileged user of the grading child can run
# Python, and leaves no copy of the reference solutions that user can read.
set -euo pipefail
AUTOGRADER=${AUTOGRADER:-/autograder}
VENV=${MUTEXT_VENV:-/opt/mutext}
SRC="$AUTOGRADER/source/mutext-src"

if ! python3 -c 'import sys, venv, ensurepip; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
    apt-get update && apt-get install -y --no-install-recommends python3 python3-venv
fi
if ! python3 -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
    echo "setup.sh: mutext needs Python 3.11 or newer; choose Gradescope's Ubuntu 24.04 base image" >&2
    exit 1
fi

python3 -m venv "$VENV"
chmod 755 "$VENV"
# not -e: the package then lives in site-packages only, not as a link to the source tree
"$VENV/bin/pip" install --quiet "$SRC"
# The child copies the modules a student may import into its own directory, so
# nobody but root needs to read the installed package (grader, solutions).
pkg=$(cd / && "$VENV/bin/python" -I -c 'import mutext, os; print(os.path.dirname(mutext.__file__))')
chmod -R go-rwx "$pkg" "$AUTOGRADER/source"
"$VENV/bin/mutext" grade --list >/dev/null
