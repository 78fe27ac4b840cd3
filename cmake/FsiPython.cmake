# FSI_PYTHON: the Python interpreter the project's Python tools run with (fsi study, the example
# solid, the Python tests). The first candidate that imports numpy, yaml, zmq and google.protobuf
# wins: Debian's /usr/bin/python3 first (python3-numpy, python3-yaml, python3-zmq,
# python3-protobuf), then the python3 on PATH. Set -DFSI_PYTHON=... to choose another; at run time
# the environment variable FSI_PYTHON overrides it.
if(NOT FSI_PYTHON)
  set(_fsi_python_candidates)
  if(EXISTS /usr/bin/python3)
    list(APPEND _fsi_python_candidates /usr/bin/python3)
  endif()
  find_program(_fsi_path_python NAMES python3)
  if(_fsi_path_python)
    list(APPEND _fsi_python_candidates ${_fsi_path_python})
  endif()
  foreach(_candidate IN LISTS _fsi_python_candidates)
    execute_process(COMMAND ${_candidate} -c "import numpy, yaml, zmq, google.protobuf"
                    RESULT_VARIABLE _fsi_python_rc OUTPUT_QUIET ERROR_QUIET)
    if(_fsi_python_rc EQUAL 0)
      set(FSI_PYTHON ${_candidate} CACHE FILEPATH "Python interpreter with numpy, yaml, zmq and protobuf")
      break()
    endif()
  endforeach()
  if(NOT FSI_PYTHON)
    message(WARNING "no python3 with numpy, yaml, zmq and protobuf found (Debian: python3-numpy python3-yaml "
                    "python3-zmq python3-protobuf); fsi study and the Python example solid will not run")
    set(FSI_PYTHON /usr/bin/python3)
  endif()
endif()
message(STATUS "FSI_PYTHON: ${FSI_PYTHON}")
