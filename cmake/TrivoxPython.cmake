# Finds what the Python module (python/) needs and sets TRIVOX_PYTHON_DEFAULT: ON where the
# interpreter with its headers, pybind11 and numpy are all found, OFF otherwise (with a line
# saying what is missing), and OFF in the sanitizer and fuzzer builds (see below).
#
# The interpreter: Python3_EXECUTABLE when given; otherwise Debian's /usr/bin/python3, the one
# that python3-numpy and python3-pytest install into. A `python3` found first on PATH (pyenv,
# conda) often lacks numpy, and the module must be built for the interpreter that runs it.
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "The Python interpreter the module is built for")
endif()

set(TRIVOX_PYTHON_DEFAULT OFF)
set(_trivox_python_missing "")
find_package(Python3 3.9 COMPONENTS Interpreter Development.Module QUIET)
if(NOT Python3_Interpreter_FOUND)
  list(APPEND _trivox_python_missing "a Python 3 interpreter (python3)")
elseif(NOT Python3_Development.Module_FOUND)
  list(APPEND _trivox_python_missing "the headers of ${Python3_EXECUTABLE} (python3-dev)")
endif()
if(Python3_Interpreter_FOUND)
  # Found through the interpreter's own pybind11 module too (python3-pybind11), so that a
  # pybind11 installed only for Python is used.
  execute_process(COMMAND ${Python3_EXECUTABLE} -c "import pybind11; print(pybind11.get_cmake_dir())"
                  OUTPUT_VARIABLE _trivox_pybind11_dir OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  execute_process(COMMAND ${Python3_EXECUTABLE} -c "import numpy"
                  RESULT_VARIABLE _trivox_numpy_status OUTPUT_QUIET ERROR_QUIET)
  if(NOT _trivox_numpy_status EQUAL 0)
    list(APPEND _trivox_python_missing "numpy for ${Python3_EXECUTABLE} (python3-numpy)")
  endif()
endif()
find_package(pybind11 2.6 CONFIG QUIET HINTS ${_trivox_pybind11_dir})
if(NOT pybind11_FOUND)
  list(APPEND _trivox_python_missing "pybind11 (pybind11-dev)")
endif()

if(TRIVOX_SANITIZE OR TRIVOX_BUILD_FUZZERS)
  # An extension built with the sanitizers cannot be loaded into the ordinary interpreter
  # without preloading their runtime, and the interpreter's own allocations then flood the
  # leak checker; the library it binds is covered by the sanitizer builds of the C++ tests.
  message(STATUS "trivox: Python module off by default in sanitizer and fuzzer builds")
elseif(_trivox_python_missing)
  list(JOIN _trivox_python_missing ", " _trivox_missing_text)
  message(STATUS "trivox: Python module off: missing ${_trivox_missing_text}")
else()
  set(TRIVOX_PYTHON_DEFAULT ON)
  message(STATUS "trivox: Python module for ${Python3_EXECUTABLE} (Python ${Python3_VERSION}, pybind11 "
                 "${pybind11_VERSION})")
endif()
