# Prints the packages an npm lock file (lockfileVersion 2 or 3) pins, one a line:
# "PATH NAME VERSION INTEGRITY", the development dependencies left out unless DEV is true.
#
#   cmake -DLOCK=web/package-lock.json [-DDEV=ON] -P cmake/npm_lock_packages.cmake
#
# scripts/setup.sh --program reads it to fetch the GUI's runtime packages (three.js) from the npm
# registry without Node.js: the tarball's SHA-512 is checked against INTEGRITY, as npm ci does.
if(NOT DEFINED LOCK)
  message(FATAL_ERROR "npm_lock_packages: give -DLOCK=FILE")
endif()
file(READ "${LOCK}" text)
string(JSON packages ERROR_VARIABLE error GET "${text}" packages)
if(error)
  message(FATAL_ERROR "npm_lock_packages: ${LOCK}: no \"packages\" object: ${error}")
endif()
string(JSON count LENGTH "${packages}")
math(EXPR last "${count} - 1")
foreach(i RANGE ${last})
  string(JSON path MEMBER "${packages}" ${i})
  if(path STREQUAL "")
    continue()  # the project itself
  endif()
  string(JSON dev ERROR_VARIABLE no_dev GET "${packages}" "${path}" dev)
  if(dev AND NOT DEV)
    continue()
  endif()
  string(JSON version GET "${packages}" "${path}" version)
  string(JSON integrity GET "${packages}" "${path}" integrity)
  # The name is what follows the last node_modules/ (a scope included: @scope/name).
  string(REGEX REPLACE "^.*node_modules/" "" name "${path}")
  execute_process(COMMAND ${CMAKE_COMMAND} -E echo "${path} ${name} ${version} ${integrity}")
endforeach()
