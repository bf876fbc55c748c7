# Sourced by the build scripts. `generator DIR` prints "-G Ninja" when ninja is installed and DIR
# is new or already a Ninja build (Ninja compiles across targets: the tests' files while the
# libraries' unity batches are still compiling, where Make waits target by target), else nothing
# (CMake cannot change the generator of a configured build folder; Make is used there).
generator() {
  command -v ninja >/dev/null || return 0
  if [[ -f "$1/CMakeCache.txt" ]] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$1/CMakeCache.txt"; then
    return 0
  fi
  echo "-G Ninja"
}
