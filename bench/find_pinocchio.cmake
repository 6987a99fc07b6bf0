# softrne_find_pinocchio(): looks for Pinocchio's C++ package (bench/ and tests/pinocchio/).
#
# Also looks in the cmeel prefix of `pip install pin` (site-packages/cmeel.prefix, which
# holds Pinocchio and its boost/urdfdom/coal); that prefix is appended to CMAKE_PREFIX_PATH
# of the calling directory only. pinocchioConfig.cmake calls find_dependency(... REQUIRED),
# a hard configure error when one is missing (typically urdfdom_headers:
# apt install liburdfdom-headers-dev), so those are looked for first.
#
# Sets in the caller's scope: SOFTRNE_PINOCCHIO_FOUND (TRUE when the imported target
# pinocchio::pinocchio_headers exists) and SOFTRNE_PINOCCHIO_MISSING (what was not found).
macro(softrne_find_pinocchio)
  set(SOFTRNE_PINOCCHIO_FOUND FALSE)
  set(SOFTRNE_PINOCCHIO_MISSING "")
  if(NOT TARGET pinocchio::pinocchio_headers)
    find_package(Python3 COMPONENTS Interpreter QUIET)
    if(Python3_Interpreter_FOUND)
      execute_process(COMMAND ${Python3_EXECUTABLE} -m cmeel cmake
        OUTPUT_VARIABLE _softrne_cmeel_prefix ERROR_QUIET OUTPUT_STRIP_TRAILING_WHITESPACE
        RESULT_VARIABLE _softrne_cmeel_rc)
      if(_softrne_cmeel_rc EQUAL 0 AND IS_DIRECTORY "${_softrne_cmeel_prefix}")
        list(APPEND CMAKE_PREFIX_PATH "${_softrne_cmeel_prefix}")
      endif()
    endif()
    set(Boost_NO_WARN_NEW_VERSIONS ON)  # CMake's FindBoost vs the wheel's newer Boost
    find_path(_softrne_pin_config_dir pinocchioConfig.cmake
      PATH_SUFFIXES lib/cmake/pinocchio share/pinocchio/cmake
      lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/pinocchio NO_CACHE)
    if(_softrne_pin_config_dir)
      foreach(_softrne_dep urdfdom_headers urdfdom coal)
        find_package(${_softrne_dep} CONFIG QUIET)
        if(NOT ${_softrne_dep}_FOUND)
          list(APPEND SOFTRNE_PINOCCHIO_MISSING ${_softrne_dep})
        endif()
      endforeach()
      if(NOT SOFTRNE_PINOCCHIO_MISSING)
        find_package(pinocchio CONFIG QUIET)
      endif()
    else()
      set(SOFTRNE_PINOCCHIO_MISSING pinocchio)
    endif()
  endif()
  if(TARGET pinocchio::pinocchio_headers)
    set(SOFTRNE_PINOCCHIO_FOUND TRUE)
  endif()
endmacro()
