#!/usr/bin/env bash
# The default build links nothing under the GPL. Two checks on a finished build:
# 1. no object of the build was compiled from a CGAL header (CGAL's 2D triangulations, which the
#    optional roadmap planner uses, are GPL-3; CGAL is header-only, so the headers are what counts);
# 2. the msim program loads no shared library of a GPL-only package that could slip in.
# Usage: check_no_gpl.sh BUILD_DIR PROGRAM
set -euo pipefail
build_dir=$1
program=$2

if [[ -f "$build_dir/build.ninja" ]] && command -v ninja > /dev/null; then
  cgal_users=$(ninja -C "$build_dir" -t deps | awk '/^[^ ].*: #deps/ {object = $1} /\/CGAL\// {print object}' | sort -u)
  if [[ -n "$cgal_users" ]]; then
    echo "compiled from CGAL headers (GPL-3):"
    echo "$cgal_users"
    exit 1
  fi
  objects=$(ninja -C "$build_dir" -t deps | grep -c ': #deps' || true)
  echo "no CGAL header in the dependencies of $objects objects"
else
  echo "not a Ninja build: the header check needs 'ninja -t deps'; skipped"
fi

# Sonames of GPL-only libraries a C++ numerics project might link (GMP, MPFR and the GNU C and
# C++ runtimes are LGPL or GPL with the runtime exception, and allowed).
gpl_only='libCGAL|libfftw3|libgsl|libreadline|libqhull|libtriangle|libmpfi|libpari|libntl'
if ldd "$program" | grep -E "$gpl_only"; then
  echo "$program loads the GPL-only libraries above"
  exit 1
fi
echo "$program: $(ldd "$program" | wc -l) shared libraries, none GPL-only"
