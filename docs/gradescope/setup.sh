#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder image.
# It installs mutext and the instructor's grader (mutext_grader: reference
# solutions, graded inputs) where the unprivileged user of the grading child
# can run Python, stores the course secret for root only, and leaves no copy
# of the solutions or of the secret that user can read.
set -euo pipefail
umask 022
AUTOGRADER=${AUTOGRADER:-/autograder}
VENV=${MUTEXT_VENV:-/opt/mutext}
SRC="$AUTOGRADER/source/mutext-src"
SECRET="$AUTOGRADER/secret"

if ! python3 -c 'import sys, venv, ensurepip; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
    apt-get update && apt-get install -y --no-install-recommends python3 python3-venv
fi
if ! python3 -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
    echo "setup.sh: mutext needs Python 3.11 or newer; choose Gradescope's Ubuntu 24.04 base image" >&2
    exit 1
fi

# The course secret: root only, outside the source tree, in a directory the
# grading child never sees (/autograder is covered in its mount namespace).
if [ -f "$AUTOGRADER/source/secret" ]; then
    install -m 600 -o root -g root "$AUTOGRADER/source/secret" "$SECRET"
    rm -f "$AUTOGRADER/source/secret"
fi
[ -s "$SECRET" ] || { echo "setup.sh: no course secret in the autograder zip (make_autograder.py packs one)" >&2; exit 1; }
chmod 600 "$SECRET"

python3 -m venv "$VENV"
chmod 755 "$VENV"
# not -e: the packages then live in site-packages only, not as links to the source tree;
# no cache: no wheel of the grader is left behind
"$VENV/bin/pip" install --quiet --no-cache-dir "$SRC" "$SRC/instructor"
# The child copies the modules a student may import into its own directory, so
# nobody but root needs to read the installed packages (the grader, its solutions).
pkgs=$(cd / && "$VENV/bin/python" -I -c '
import os, mutext, mutext_grader
for m in (mutext, mutext_grader):
    print(os.path.dirname(m.__file__))')
# shellcheck disable=SC2086 - one directory per line, no spaces in site-packages paths
chmod -R go-rwx $pkgs "$AUTOGRADER/source"
"$VENV/bin/mutext-grade" --list >/dev/null
