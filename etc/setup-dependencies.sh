#!/usr/bin/env bash
# Installs what the project needs on a Debian bookworm machine and prepares the OpenFOAM v1912
# development tree (headers + wmake) that Debian's binary package lacks. Idempotent: a second run
# checks, finds everything in place and downloads nothing.
#
#   etc/setup-dependencies.sh [CACHE_DIR]      (default: <project>/.cache)
#
# What it does, in order:
#  1. apt-get install the Debian packages (only those missing).
#  2. pip install the Python packages the scripts need (only those missing).
#  3. fetch the OpenFOAM source package pinned to the installed libopenfoam version (needs a
#     deb-src entry, which is added if absent), extract only wmake, etc, bin and the src modules
#     a solver needs, bootstrap wmake and create the lnInclude directories.
set -euo pipefail

projectDir=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cacheDir=${1:-$projectDir/.cache}
mkdir -p "$cacheDir"
log() { printf '[setup] %s\n' "$*"; }
die() { printf '[setup] ERROR: %s\n' "$*" >&2; exit 1; }

sudo=""
if [ "$(id -u)" -ne 0 ]; then command -v sudo >/dev/null && sudo=sudo || die "run as root or install sudo"; fi

# ---- 1. Debian packages --------------------------------------------------------------------------
debianPackages="openfoam libopenfoam liggghts libliggghts-dev libeigen3-dev libfftw3-dev libfftw3-mpi-dev libsuitesparse-dev libopenblas0-serial libopenmpi-dev openmpi-bin
 g++ make cmake bzip2 libgtest-dev dpkg-dev python3 python3-pip"
missing=""
for p in $debianPackages; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
    log "installing Debian packages:$missing"
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -q
    # shellcheck disable=SC2086
    $sudo apt-get install -y -q --no-install-recommends $missing
else
    log "Debian packages already installed"
fi

# ---- 2. Python packages --------------------------------------------------------------------------
python=${FDM_PYTHON:-python3}
pyMissing=""
for m in numpy scipy matplotlib pytest wheel; do   # wheel: pip install -e scripts without the network
    "$python" -c "import $m" 2>/dev/null || pyMissing="$pyMissing $m"
done
if [ -n "$pyMissing" ]; then
    log "installing Python packages:$pyMissing"
    # shellcheck disable=SC2086
    "$python" -m pip install -q $pyMissing 2>/dev/null \
        || "$python" -m pip install -q --break-system-packages $pyMissing
else
    log "Python packages already installed"
fi

# ---- 3. OpenFOAM v1912 development tree ----------------------------------------------------------
ofPrefix=$cacheDir/openfoam
ofDir=$ofPrefix/OpenFOAM-v1912
srcVersion=$(dpkg-query -W -f='${source:Version}' libopenfoam)      # e.g. 1912.200626-1
upstreamVersion=${srcVersion%-*}                                      # 1912.200626
stamp=$ofPrefix/.complete-$srcVersion
modules="OpenFOAM OSspecific/POSIX finiteVolume meshTools fileFormats surfMesh"

if [ -f "$stamp" ]; then
    log "OpenFOAM $srcVersion development tree ready in $ofDir"
else
    mkdir -p "$ofPrefix/debsrc"
    tarball=$ofPrefix/debsrc/openfoam_$upstreamVersion.orig.tar.bz2
    if [ ! -f "$tarball" ]; then
        if ! grep -rqs "^deb-src\|Types:.*deb-src" /etc/apt/sources.list /etc/apt/sources.list.d/; then
            log "adding a deb-src entry for bookworm"
            $sudo tee /etc/apt/sources.list.d/fdm-debsrc.sources >/dev/null <<'EOF'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
            $sudo apt-get update -q
        fi
        log "downloading the OpenFOAM source package openfoam=$srcVersion"
        (cd "$ofPrefix/debsrc" && apt-get source -q --download-only "openfoam=$srcVersion") \
            || die "apt-get source openfoam=$srcVersion failed (is a deb-src entry reachable?)"
    fi
    top=$( (tar -tjf "$tarball" 2>/dev/null || true) | head -1 | cut -d/ -f1)   # top folder name
    log "extracting wmake, etc, bin and src/{$modules} from $(basename "$tarball")"
    rm -rf "$ofDir" && mkdir -p "$ofDir"
    members="$top/META-INFO $top/bin $top/etc $top/wmake"
    for m in $modules; do members="$members $top/src/$m"; done
    # shellcheck disable=SC2086
    tar -xjf "$tarball" -C "$ofDir" --strip-components=1 $members
    # Debian's configured etc (ThirdParty set to system) replaces upstream's.
    cp -a /usr/share/openfoam/etc/. "$ofDir/etc/"
    echo "export WM_PROJECT_USER_DIR=\"$ofPrefix/user\"" > "$ofDir/etc/prefs.sh"
    (
        set +eu
        export USER=${USER:-$(id -un)}
        # shellcheck disable=SC1091
        . "$ofDir/etc/bashrc"
        set -e
        log "bootstrapping wmake"
        "$WM_DIR/src/Allmake" >/dev/null
        for m in $modules; do wmakeLnInclude -u "$WM_PROJECT_DIR/src/$m" >/dev/null; done
    )
    touch "$stamp"
    log "OpenFOAM development tree ready in $ofDir"
fi
