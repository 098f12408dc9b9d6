# A private, fixed copy of a CMake package whose imported targets name files that do not exist.
#
# Why: Debian 13's and sid's ParaView and VTK packages list their Python extension modules under
# the name CMake's install step gave them (`vtkmodules/vtkCommonCore.so`), but Debian installs them
# with the interpreter's ABI suffix (`vtkCommonCore.cpython-313-x86_64-linux-gnu.so`). CMake checks
# that every imported file exists, so `find_package(ParaView)` stops before the plugin (which uses
# none of those Python modules) is even configured. We never write into /usr: when a package has
# such entries, the build uses a private copy of its directory in which each missing file is
# replaced by the one file next to it that has the same name plus an ABI suffix (none found: the
# entry stays, and CMake's own error names it). Everything else still comes from the original
# package: headers, libraries and tools are the system's, as before.
# Packages without such entries (Debian 12, Kitware's binaries) are used as they are.

# Sets `out_var` to `package_dir` itself, or to the fixed copy under the build tree.
function(rgmc_fixed_package_dir out_var package_dir)
  get_filename_component(package_dir "${package_dir}" REALPATH)
  set("${out_var}" "${package_dir}" PARENT_SCOPE)
  file(GLOB_RECURSE config_files RELATIVE "${package_dir}" "${package_dir}/*-targets-*.cmake")
  set(fixes) # pairs "file|old|new"
  foreach (config_file IN LISTS config_files)
    # The matching `X-targets.cmake` computes the prefix: its directory, up one level per line.
    string(REGEX REPLACE "-targets-[^/]*\\.cmake$" "-targets.cmake" targets_file "${config_file}")
    if (NOT EXISTS "${package_dir}/${targets_file}")
      continue ()
    endif ()
    file(STRINGS "${package_dir}/${targets_file}" levels
      REGEX "^get_filename_component\\(_IMPORT_PREFIX \"\\\${_IMPORT_PREFIX}\" PATH\\)")
    get_filename_component(prefix "${package_dir}/${targets_file}" DIRECTORY)
    foreach (level IN LISTS levels)
      get_filename_component(prefix "${prefix}" DIRECTORY)
    endforeach ()
    file(STRINGS "${package_dir}/${config_file}" checks REGEX "_cmake_import_check_files_for_")
    foreach (check IN LISTS checks)
      string(REGEX MATCHALL "\"\\\${_IMPORT_PREFIX}/[^\"]+\"" paths "${check}")
      foreach (path IN LISTS paths)
        string(REGEX REPLACE "^\"\\\${_IMPORT_PREFIX}/(.*)\"$" "\\1" relative "${path}")
        if (EXISTS "${prefix}/${relative}" OR NOT relative MATCHES "\\.so$")
          continue ()
        endif ()
        string(REGEX REPLACE "\\.so$" "" stem "${relative}")
        file(GLOB candidates "${prefix}/${stem}.*.so")
        list(LENGTH candidates count)
        if (count EQUAL 1)
          get_filename_component(name "${candidates}" NAME)
          get_filename_component(directory "${relative}" DIRECTORY)
          list(APPEND fixes "${config_file}|${relative}|${directory}/${name}")
        endif ()
      endforeach ()
    endforeach ()
  endforeach ()
  if (NOT fixes)
    return ()
  endif ()

  # The copy: each file that needs a fix, and each package config next to one (it includes its
  # targets files from its own folder), is a real, fixed copy; every other CMake file is a one-line
  # stub that includes the original, so it runs where it always did and computes the same paths;
  # every other file is a link to the original.
  get_filename_component(name "${package_dir}" NAME)
  set(copy "${CMAKE_BINARY_DIR}/fixed-cmake-packages/${name}")
  file(REMOVE_RECURSE "${copy}")
  set(fixed_files)
  set(fixed_dirs)
  foreach (fix IN LISTS fixes)
    string(REPLACE "|" ";" fix "${fix}")
    list(GET fix 0 config_file)
    string(REGEX REPLACE "-targets-[^/]*\\.cmake$" "-targets.cmake" targets_file "${config_file}")
    get_filename_component(dir "./${config_file}" DIRECTORY)
    list(APPEND fixed_files "${config_file}" "${targets_file}")
    list(APPEND fixed_dirs "${dir}")
  endforeach ()
  file(GLOB_RECURSE originals LIST_DIRECTORIES false RELATIVE "${package_dir}" "${package_dir}/*")
  foreach (file IN LISTS originals)
    get_filename_component(dir "./${file}" DIRECTORY)
    set(original "${package_dir}/${file}")
    if (file IN_LIST fixed_files OR (dir IN_LIST fixed_dirs AND file MATCHES "(-config|Config)\\.cmake$"))
      file(READ "${original}" text)
      # A targets file computes the prefix from its own location: give it the original one.
      string(REPLACE "get_filename_component(_IMPORT_PREFIX \"\${CMAKE_CURRENT_LIST_FILE}\" PATH)"
        "get_filename_component(_IMPORT_PREFIX \"${original}\" PATH)" text "${text}")
      file(WRITE "${copy}/${file}" "${text}")
    elseif (file MATCHES "\\.cmake$")
      file(WRITE "${copy}/${file}" "include(\"${original}\")\n")
    else ()
      get_filename_component(link_dir "${copy}/${file}" DIRECTORY)
      file(MAKE_DIRECTORY "${link_dir}")
      file(CREATE_LINK "${original}" "${copy}/${file}" SYMBOLIC)
    endif ()
  endforeach ()
  list(LENGTH fixes count)
  foreach (fix IN LISTS fixes)
    string(REPLACE "|" ";" fix "${fix}")
    list(GET fix 0 file)
    list(GET fix 1 old)
    list(GET fix 2 new)
    file(READ "${copy}/${file}" text)
    string(REPLACE "\${_IMPORT_PREFIX}/${old}\"" "\${_IMPORT_PREFIX}/${new}\"" text "${text}")
    file(WRITE "${copy}/${file}" "${text}")
  endforeach ()
  message(STATUS "${name}: ${count} imported Python modules named without their ABI suffix; "
    "using a fixed copy of the CMake package in ${copy} (see CMake/rgmcFixedPackage.cmake)")
  set("${out_var}" "${copy}" PARENT_SCOPE)
endfunction ()

# Finds the newest `<name>-*/<name>-config.cmake` in the system's CMake package folders.
function(rgmc_system_package_dir out_var name)
  set(found)
  foreach (prefix IN LISTS CMAKE_SYSTEM_PREFIX_PATH)
    file(GLOB dirs "${prefix}/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/${name}-*"
      "${prefix}/lib/cmake/${name}-*")
    foreach (dir IN LISTS dirs)
      if (EXISTS "${dir}/${name}-config.cmake")
        list(APPEND found "${dir}")
      endif ()
    endforeach ()
  endforeach ()
  if (found)
    list(SORT found COMPARE NATURAL ORDER DESCENDING)
    list(GET found 0 found)
  endif ()
  set("${out_var}" "${found}" PARENT_SCOPE)
endfunction ()

# Points ParaView_DIR (and VTK_DIR, for a ParaView built against an external VTK) at packages
# whose imported files exist. A directory the user gave is checked the same way.
function(rgmc_use_fixed_paraview_packages)
  foreach (name IN ITEMS paraview vtk)
    if (name STREQUAL "paraview")
      set(variable ParaView_DIR)
    else ()
      set(variable VTK_DIR)
    endif ()
    set(dir "${${variable}}")
    if (NOT dir OR NOT EXISTS "${dir}/${name}-config.cmake")
      rgmc_system_package_dir(dir "${name}")
    endif ()
    if (dir)
      rgmc_fixed_package_dir(fixed "${dir}")
      if (NOT fixed STREQUAL dir)
        set("${variable}" "${fixed}" CACHE PATH "The ${name} CMake package (a fixed copy)" FORCE)
      endif ()
    endif ()
  endforeach ()
endfunction ()
