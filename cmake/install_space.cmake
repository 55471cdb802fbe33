# The install space (`make install PREFIX=DIR`, or a plain `catkin_make install`): everything a user needs with
# the checkout gone. See docs/install.md. Included by CMakeLists.txt after catkin_package().
#
# Where Python comes from: PREFIX/.venv (cmake/install_venv.sh), a venv over Debian's /usr/bin/python3 with the
# pinned PyPI packages of requirements.txt. Every installed Python program names PREFIX/.venv/bin/python on its
# first line, so it finds Debian's rospy and PyBullet, xacro, numpy, ray whatever python3 is first on PATH.

# The venv first: the rules below point programs at it. At install time, so PREFIX is the one installed into.
install(CODE "
  execute_process(COMMAND bash \"${CMAKE_CURRENT_SOURCE_DIR}/cmake/install_venv.sh\"
    \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}\" \"\${CMAKE_INSTALL_PREFIX}\"
    \"${DIFFBOT_SIM_ROOT}/requirements.txt\" \"${DIFFBOT_SIM_ROOT}/.venv\"
    RESULT_VARIABLE _diffbot_venv_status)
  if(NOT _diffbot_venv_status EQUAL 0)
    message(FATAL_ERROR \"diffbot_sim: the install space's venv could not be made (above)\")
  endif()")

# diffbot_sim_venv_first_line(<destination> <file>...): at install time, the first line of each installed
# <destination>/<file name> becomes `#!PREFIX/.venv/bin/python` (catkin_install_python writes
# `#!/usr/bin/env python`, whichever python is first on PATH).
function(diffbot_sim_venv_first_line destination)
  set(files "")
  foreach(file ${ARGN})
    get_filename_component(name "${file}" NAME)
    list(APPEND files "\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${destination}/${name}")
  endforeach()
  install(CODE "execute_process(COMMAND sed -i \"1s|^#!.*|#!\${CMAKE_INSTALL_PREFIX}/.venv/bin/python|\" ${files}
    RESULT_VARIABLE _status)
  if(NOT _status EQUAL 0)
    message(FATAL_ERROR \"diffbot_sim: could not point ${destination}'s scripts at the venv\")
  endif()")
endfunction()

# The nodes: every file of scripts/ (a new one needs no edit here).
file(GLOB DIFFBOT_SIM_SCRIPTS LIST_DIRECTORIES false CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/scripts/*)
catkin_install_python(PROGRAMS ${DIFFBOT_SIM_SCRIPTS} DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
diffbot_sim_venv_first_line(${CATKIN_PACKAGE_BIN_DESTINATION} ${DIFFBOT_SIM_SCRIPTS})

# What launch files, the batch examples and users' own files find under $(find diffbot_sim). From the checkout's
# real folders: in catkin_ws/src/diffbot_sim they are links (tools/setup.sh), which install() would copy as
# links, dangling in the install space. Likewise package.xml, which catkin_package() installs as it finds it.
install(DIRECTORY ${DIFFBOT_SIM_ROOT}/launch ${DIFFBOT_SIM_ROOT}/urdf ${DIFFBOT_SIM_ROOT}/config
  ${DIFFBOT_SIM_ROOT}/worlds ${DIFFBOT_SIM_ROOT}/rviz ${DIFFBOT_SIM_ROOT}/maps ${DIFFBOT_SIM_ROOT}/examples
  DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
install(FILES ${DIFFBOT_SIM_ROOT}/package.xml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})
# The pins the venv was made from, to repair or rebuild it: PREFIX/.venv/bin/python -m pip install -r <this>.
install(FILES ${DIFFBOT_SIM_ROOT}/requirements.txt DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})

# The batch examples' scenarios (examples/batch/*.yaml name diffbot_sim/tests/rostest/<x>.test) and, beside them
# (roslaunch finds a node anywhere in the package's share folder), the test nodes those files start
# (`type="..."` of pkg diffbot_sim, from tests/rostest/ or tests/integration/) with the integration tests'
# helper modules, which the nodes import from their own folder. Plain install(PROGRAMS), not
# catkin_install_python: a devel-space relay would take the node away from its helpers.
file(GLOB _diffbot_batch_tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/tests/rostest/*.test)
set(_diffbot_test_nodes "")
foreach(_test ${_diffbot_batch_tests})
  file(STRINGS ${_test} _lines REGEX "pkg=\"diffbot_sim\"")
  foreach(_line ${_lines})
    if(_line MATCHES "type=\"([^\"]+\\.py)\"")
      foreach(_dir tests/rostest tests/integration)
        if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${_dir}/${CMAKE_MATCH_1})
          list(APPEND _diffbot_test_nodes ${CMAKE_CURRENT_SOURCE_DIR}/${_dir}/${CMAKE_MATCH_1})
        endif()
      endforeach()
    endif()
  endforeach()
endforeach()
list(REMOVE_DUPLICATES _diffbot_test_nodes)
file(GLOB _diffbot_test_helpers CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/tests/integration/*.py)
list(FILTER _diffbot_test_helpers EXCLUDE REGEX "/test_[^/]*$")
set(_diffbot_rostest_dir ${CATKIN_PACKAGE_SHARE_DESTINATION}/tests/rostest)
install(FILES ${_diffbot_batch_tests} DESTINATION ${_diffbot_rostest_dir})
install(PROGRAMS ${_diffbot_test_nodes} DESTINATION ${_diffbot_rostest_dir})
install(FILES ${_diffbot_test_helpers} DESTINATION ${_diffbot_rostest_dir})
diffbot_sim_venv_first_line(${_diffbot_rostest_dir} ${_diffbot_test_nodes})
# Fixture files the batch scenarios load from tests/data ($(find diffbot_sim)/tests/data/<kind>/<file> in a
# tests/rostest/*.test): installed where those lines look.
foreach(_test ${_diffbot_batch_tests})
  file(STRINGS ${_test} _lines REGEX "\\$\\(find diffbot_sim\\)/tests/data/")
  foreach(_line ${_lines})
    string(REGEX MATCHALL "\\$\\(find diffbot_sim\\)/tests/data/[A-Za-z0-9_./-]+" _uses "${_line}")
    foreach(_use ${_uses})
      string(REPLACE "$(find diffbot_sim)/" "" _rel "${_use}")
      get_filename_component(_rel_dir ${_rel} DIRECTORY)
      install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/${_rel} DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION}/${_rel_dir})
    endforeach()
  endforeach()
endforeach()

# catkin writes the install space's _setup_util.py (run by every `source PREFIX/setup.bash`) with the build's
# Python on its first line. In catkin_ws (tools/setup.sh) that is the checkout's .venv, which a plain
# `catkin_make install` would leave the install space depending on: point it at the install space's own venv.
# (`make install` builds with /usr/bin/python3, which needs nothing.)
string(FIND "${PYTHON_EXECUTABLE}" "${DIFFBOT_SIM_ROOT}/" _diffbot_python_in_checkout)
if(_diffbot_python_in_checkout EQUAL 0 AND CATKIN_INSTALL_INTO_PREFIX_ROOT)
  install(CODE "execute_process(COMMAND sed -i
    \"1s|^#!${PYTHON_EXECUTABLE}\$|#!\${CMAKE_INSTALL_PREFIX}/.venv/bin/python|\"
    \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/_setup_util.py\")")
endif()
