#!/usr/bin/env bash
# Installs the project's Python package fdmsubgrid (scripts/fdmsubgrid) the way Python users expect:
# `pip install -e scripts`, an editable install into the interpreter ./Allwmake uses ($FDM_PYTHON, else
# python3; the user's site-packages if the interpreter's is not writable). `pip show fdmsubgrid` then
# knows it, `import fdmsubgrid` works from any folder or notebook, and the fdmProfiles command declared
# in scripts/pyproject.toml is installed beside the interpreter. Editable: the installed package is this
# checkout's scripts/fdmsubgrid, edits need no reinstall. ./Allwmake runs it; docs/install.md.
#
# The build uses the setuptools and wheel already installed (--no-build-isolation: no network; setuptools
# 64 or later builds editable wheels, etc/setup-dependencies.sh installs wheel); without them, pip's own
# isolated build, which fetches them. If neither works (an offline machine without wheel, a pip older than
# 21.3), a .pth file in site-packages makes the package importable all the same, without the command and
# without pip knowing of it; the reason is printed.
#   etc/install-python-package.sh
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
python=${FDM_PYTHON:-python3}
log=${FDM_CACHE:-$root/.cache}/log.pip
mkdir -p "$(dirname "$log")"
: > "$log"

# pip install ARGS, retried with --break-system-packages where the interpreter is externally managed
pipInstall() {
    "$python" -m pip install -q --no-deps "$@" >>"$log" 2>&1 \
        || { grep -q "externally-managed-environment" "$log" \
             && "$python" -m pip install -q --no-deps --break-system-packages "$@" >>"$log" 2>&1; }
}

# the site-packages folders a former install's .pth file may sit in
sitePackages() {
    "$python" - <<'PY'
import site, sysconfig
for d in dict.fromkeys((sysconfig.get_paths()["purelib"], site.getusersitepackages())):
    print(d)
PY
}

if pipInstall --no-build-isolation -e "$root/scripts" || pipInstall -e "$root/scripts"; then
    # the .pth file of earlier set-ups is replaced by pip's own
    while read -r d; do rm -f "$d/fdmsubgrid.pth"; done < <(sitePackages)
    where=$("$python" -m pip show fdmsubgrid 2>/dev/null | sed -n 's/^Editable project location: //p')
    echo "[build] fdmsubgrid installed by pip (editable, from ${where:-$root/scripts})"
    # pyenv finds a new command through a shim, made by a rehash
    if command -v pyenv >/dev/null; then pyenv rehash 2>/dev/null || true; fi
    scripts=$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["scripts"])')
    command -v fdmProfiles >/dev/null \
        || echo "[build] note: fdmProfiles was installed in $scripts or your user's bin folder, which is not on the PATH (. etc/bashrc puts scripts/fdmProfiles there)"
else
    # the build's own messages (e.g. "invalid command 'bdist_wheel'": no wheel package; "No matching
    # distribution found for setuptools": no network for the isolated build), not pip's summary lines
    reason=$(grep -E "^ +(error|ERROR): " "$log" | grep -v "subprocess-exited-with-error" | sed 's/^ *//' \
             | sort -u | paste -sd ';' - | sed 's/;/; /g')
    reason=${reason:-see the log}
    dir=""
    while read -r d; do
        if mkdir -p "$d" 2>/dev/null && [ -w "$d" ]; then dir=$d; break; fi
    done < <(sitePackages)
    if [ -z "$dir" ]; then
        echo "[build] WARNING: pip could not install fdmsubgrid ($reason) and no site-packages is writable: add $root/scripts to PYTHONPATH"
        exit 0
    fi
    echo "$root/scripts" > "$dir/fdmsubgrid.pth"
    echo "[build] WARNING: pip could not install fdmsubgrid ($reason; $log): made importable by $dir/fdmsubgrid.pth instead, without the fdmProfiles command outside . etc/bashrc (docs/install.md)"
fi
( cd / && "$python" -c "import fdmsubgrid" ) \
    || { echo "[build] ERROR: $python cannot import fdmsubgrid after the install ($log)"; exit 1; }
