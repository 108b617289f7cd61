# crossrt_add_class(<target> <Class> BACKEND vulkan|cpu [SOURCES file...]
#                   [COMPOSE Interface=Implementation...] [VIRTUAL_LEVEL 1|2|3]
#                   [EXECUTION_MODE wavefront|megakernel] [NAME <Generated>])
#
# Translates class <Class> into <Class>_Vulkan (or <Class>_CPU), in the build tree, and adds the
# generated sources, their include path and the runtime to <target>. A class in a namespace is
# named with it (demo::Render); its generated classes are declared in the same namespace. SOURCES
# are the files that define <Class>'s member functions; without it, the sources of <target> that
# define them are found, whatever their names (a class whose members are all defined in its header
# is found through the headers they include). The translation re-runs when any file it read
# changes (depfile), and writes only files whose contents changed, so an unchanged class
# recompiles nothing.
#
# COMPOSE (paper 3.6): kernels that call Interface's methods through a member (a shared_ptr,
# unique_ptr or pointer) run Implementation's code on the GPU, and its data is uploaded with the
# class's. Implementation's source files are added to SOURCES when it was registered with
# crossrt_register_implementation() (litert's BVHScene is); otherwise list them in SOURCES.
#
# VIRTUAL_LEVEL (paper 3.9): how kernels' virtual calls through a std::vector of pointers reach the
# objects on the GPU: 1 = every element in one array of equal slots, 2 (default) = each class's
# objects in a buffer of their own, 3 = as 2, and where the device has ray tracing pipelines, kernels
# run as ray generation shaders whose virtual calls execute a callable shader per class, and whose
# composed traversals' leaf calls are intersection shaders (paper 3.10). The class's code is the
# same for all three.
#
# EXECUTION_MODE (paper 2.1 and 4.4): how a control function's thread loop that calls several kernels
# (for (y) for (x) { float4 ray; kernel_A(x, y, &ray); kernel_B(x, y, &ray); }) runs on the GPU:
# wavefront (default) = one dispatch per kernel call, per-thread locals kept in buffers between
# them; megakernel = the whole loop body in one shader, locals in registers. Both are generated;
# this picks the one the class starts with, and SetExecutionMode() switches at run time.
#
# NAME: the generated class's name (and its files' and global symbols'), instead of <Class>_Vulkan,
# <Class>_CPU or <Class>_ISPC: several translations of one class, at different VIRTUAL_LEVELs say,
# then link into one program (crossrt_add_class(app Render VIRTUAL_LEVEL 1 NAME Render_VulkanLevel1)).
#
# The translation goes through the build tree's daemon (crossrtd, started on demand, exits when
# idle), which keeps parsed headers warm; set CROSSRT_NO_DAEMON=1 to translate in-process.
#
# CROSSRT_REMOTE_STORAGE (a cache variable, or the environment variable of the same name at build
# time, which wins): remote caches a team shares translations through, e.g.
# "redis://cache.lab:6379 http://cache.lab/crossrt|read-only" (docs/remote-cache.md). Paths under
# the build tree and the top-level source folder are stored relative to them.
# CROSSRT_REMOTE_KEY_FILE (a cache variable): a file holding the team's key; with it every entry is
# signed (HMAC-SHA256) and entries that do not verify are translated locally instead. The
# environment's CROSSRT_REMOTE_KEY (the key) and CROSSRT_REMOTE_KEY_FILE win. Never put the key
# itself in a CMake variable: it would land in build.ninja.
#
# Works from the source tree (add_subdirectory) and from an installed package (find_package).
include_guard(GLOBAL)

# BACKEND ispc: the ISPC compiler (found on PATH unless given) and the targets every ISPC class is
# compiled for, dispatched at run time (crossrt::IspcPick in IspcSupport.h lists the same ISAs).
find_program(CROSSRT_ISPC_EXECUTABLE ispc DOC "The ISPC compiler, for crossrt_add_class(... BACKEND ispc)")
set(CROSSRT_ISPC_TARGETS sse4-i32x4 avx2-i32x8 avx512skx-x16)
# ISPC's warnings as errors where generated code is compiled (this tree sets it: generated kernels
# compile without a warning; performance remarks are off either way).
option(CROSSRT_ISPC_WERROR "Compile the generated ISPC kernels with --werror" OFF)

set(CROSSRT_REMOTE_STORAGE "" CACHE STRING
    "Remote translation caches: redis://host[:port] or http[s]://host/path, space-separated, each with optional |read-only")
set(CROSSRT_REMOTE_KEY_FILE "" CACHE FILEPATH
    "A file holding the team key that signs and verifies remote cache entries (docs/remote-cache.md, Trust)")

# Registers the source files that define Implementation's methods, so that
# crossrt_add_class(... COMPOSE Interface=Implementation) parses them (absolute paths).
function(crossrt_register_implementation impl)
  cmake_parse_arguments(ARG "" "" "SOURCES" ${ARGN})
  set(abs "")
  foreach(s IN LISTS ARG_SOURCES)
    get_filename_component(a "${s}" ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    list(APPEND abs "${a}")
  endforeach()
  set_property(GLOBAL PROPERTY CROSSRT_IMPLEMENTATION_SOURCES_${impl} "${abs}")
endfunction()

function(crossrt_add_class target class)
  cmake_parse_arguments(ARG "" "BACKEND;VIRTUAL_LEVEL;EXECUTION_MODE;NAME" "SOURCES;COMPOSE" ${ARGN})
  if(NOT ARG_BACKEND)
    set(ARG_BACKEND vulkan)
  endif()
  string(TOLOWER "${ARG_BACKEND}" backend)
  if(backend STREQUAL "vulkan")
    set(suffix Vulkan)
  elseif(backend STREQUAL "cpu")
    set(suffix CPU)
  elseif(backend STREQUAL "ispc")
    set(suffix ISPC)
    if(NOT CROSSRT_ISPC_EXECUTABLE)
      message(FATAL_ERROR "crossrt_add_class(${target} ${class} BACKEND ispc): no ISPC compiler was found. Install it "
                          "from your distribution (e.g. 'apt-get install ispc' where packaged) or from Intel's release "
                          "archives (https://github.com/ispc/ispc/releases), then put 'ispc' on PATH or set "
                          "-DCROSSRT_ISPC_EXECUTABLE=/path/to/ispc. BACKEND cpu runs the same class with OpenMP alone.")
    endif()
  else()
    message(FATAL_ERROR "crossrt_add_class(${target} ${class}): BACKEND must be vulkan, cpu or ispc, not '${ARG_BACKEND}'")
  endif()
  if(NOT TARGET ${target})
    message(FATAL_ERROR "crossrt_add_class: '${target}' is not a target")
  endif()
  # A class in a namespace (demo::Render) is translated by that name; files, folders and targets
  # take the class's own name (Render_Vulkan), and the generated class joins the namespace.
  string(REGEX REPLACE "^.*::" "" name "${class}")
  set(gen ${name}_${suffix})  # the generated class, its folder and files
  set(name_args "")
  if(ARG_NAME)
    if(NOT ARG_NAME MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
      message(FATAL_ERROR "crossrt_add_class(${target} ${class}): NAME is the generated class's name, a C++ identifier, not '${ARG_NAME}'")
    endif()
    set(gen ${ARG_NAME})
    list(APPEND name_args --name ${ARG_NAME})
  endif()
  # The generated class's folder and files are named after it: one translation per name in a directory.
  get_property(generated DIRECTORY PROPERTY CROSSRT_GENERATED_CLASSES)
  if(gen IN_LIST generated)
    message(FATAL_ERROR "crossrt_add_class(${target} ${class} BACKEND ${backend}): ${gen} is already generated in this directory "
                        "(by an earlier crossrt_add_class, for this target or another): give this translation a name of its own "
                        "with NAME, e.g. NAME ${gen}_${target}, and create it with Create${gen}_${target}()")
  endif()
  set_property(DIRECTORY APPEND PROPERTY CROSSRT_GENERATED_CLASSES ${gen})

  set(sources ${ARG_SOURCES})
  set(candidates "")
  set(candidate_args "")
  if(NOT sources)
    # The target's C++ sources as the build has them (also those added after this call), less the
    # files CrossRT generates: the client keeps the ones that define the class's member functions,
    # whatever their names, and never parses one (main.cpp) only because it is in the target.
    set(all_sources "$<TARGET_PROPERTY:${target},SOURCES>")
    set(cpp_sources "$<FILTER:${all_sources},INCLUDE,\\.(cpp|cc|cxx|C|c\\+\\+)$>")
    set(candidates "$<FILTER:${cpp_sources},EXCLUDE,/crossrt/[^/]+_(Vulkan|CPU|ISPC)/>")
    set(candidate_args --source-dir "$<TARGET_PROPERTY:${target},SOURCE_DIR>"
        "$<$<BOOL:${candidates}>:--candidate$<SEMICOLON>$<JOIN:${candidates},$<SEMICOLON>--candidate$<SEMICOLON>>>")
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${name}.cpp)
      list(APPEND candidate_args --candidate ${CMAKE_CURRENT_SOURCE_DIR}/${name}.cpp)
    endif()
  endif()
  set(option_args ${name_args})
  foreach(c IN LISTS ARG_COMPOSE)
    if(NOT c MATCHES "^[A-Za-z_][A-Za-z0-9_]*=[A-Za-z_][A-Za-z0-9_]*$")
      message(FATAL_ERROR "crossrt_add_class(${target} ${class}): COMPOSE takes Interface=Implementation (e.g. ISceneObject=BVHScene), not '${c}'")
    endif()
    string(REGEX REPLACE "^.*=" "" impl "${c}")
    get_property(impl_sources GLOBAL PROPERTY CROSSRT_IMPLEMENTATION_SOURCES_${impl})
    list(APPEND sources ${impl_sources})
    list(APPEND option_args --compose "${c}")
  endforeach()
  if(ARG_VIRTUAL_LEVEL)
    if(NOT ARG_VIRTUAL_LEVEL MATCHES "^[123]$")
      message(FATAL_ERROR "crossrt_add_class(${target} ${class}): VIRTUAL_LEVEL is 1 (one array of equal slots), 2 (a buffer per class) or 3 (2, plus callable and intersection shaders), not '${ARG_VIRTUAL_LEVEL}'")
    endif()
    list(APPEND option_args --virtual-level ${ARG_VIRTUAL_LEVEL})
  endif()
  if(ARG_EXECUTION_MODE)
    if(NOT ARG_EXECUTION_MODE MATCHES "^(wavefront|megakernel)$")
      message(FATAL_ERROR "crossrt_add_class(${target} ${class}): EXECUTION_MODE is wavefront (one dispatch per kernel call) or megakernel (one shader per thread loop), not '${ARG_EXECUTION_MODE}'")
    endif()
    list(APPEND option_args --execution-mode ${ARG_EXECUTION_MODE})
  endif()
  set(abs_sources "")
  set(source_args "")
  foreach(s IN LISTS sources)
    get_filename_component(a "${s}" ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    list(APPEND abs_sources "${a}")
    list(APPEND source_args --source "${a}")
  endforeach()

  # A named class's folder is inside the default one's, so that the filter on the target's sources
  # above keeps every generated file out.
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/crossrt/${name}_${suffix})
  if(ARG_NAME)
    set(out_dir ${out_dir}/${gen})
  endif()
  set(outputs ${out_dir}/${gen}.h ${out_dir}/${gen}.cpp)
  if(suffix STREQUAL "Vulkan")
    list(APPEND outputs ${out_dir}/${gen}_shaders.cpp)
  elseif(suffix STREQUAL "ISPC")
    set(ispc_source ${out_dir}/${gen}_kernels.ispc)
    list(APPEND outputs ${ispc_source})
  endif()

  # Parse the class as the target compiles it: its include paths, definitions and standard, plus
  # the CrossRT libraries' headers. (COMPILE_OPTIONS are left out: they may hold
  # $<COMPILE_LANGUAGE:...> expressions, which a custom command cannot evaluate.)
  set(inc "$<TARGET_PROPERTY:${target},INCLUDE_DIRECTORIES>")
  set(defs "$<TARGET_PROPERTY:${target},COMPILE_DEFINITIONS>")
  set(std "$<TARGET_PROPERTY:${target},CXX_STANDARD>")
  set(features "$<TARGET_PROPERTY:${target},COMPILE_FEATURES>")
  set(compile_args "$<$<BOOL:${inc}>:-I$<JOIN:${inc},$<SEMICOLON>-I>>")
  foreach(lib crossrt::litemath crossrt::liteimage crossrt::litert crossrt::litebvh)
    set(lib_inc "$<TARGET_PROPERTY:${lib},INTERFACE_INCLUDE_DIRECTORIES>")
    list(APPEND compile_args "$<$<BOOL:${lib_inc}>:-I$<JOIN:${lib_inc},$<SEMICOLON>-I>>")
  endforeach()
  list(APPEND compile_args
    "$<$<BOOL:${defs}>:-D$<JOIN:${defs},$<SEMICOLON>-D>>"
    "$<$<BOOL:${std}>:-std=c++${std}>"
    "${features}")  # cxx_std_NN: the engine takes the highest standard asked for

  if(TARGET crossrt OR CROSSRT_TRANSLATOR_IN_TREE)  # in-tree: the target may be defined later
    set(translator $<TARGET_FILE:crossrt>)
    # The engine lives in the daemon and the in-process module, not in the client: a change to it
    # must translate again too.
    set(translator_dep crossrt crossrtd crossrt_engine_plugin)
  else()
    set(translator $<TARGET_FILE:crossrt::crossrt>)
    set(translator_dep crossrt::crossrt)
  endif()

  list(GET outputs 0 first_output)
  add_custom_command(
    OUTPUT ${outputs}
    COMMAND ${translator} translate
            --class ${class} --backend ${backend} --out ${out_dir}
            ${source_args} ${candidate_args} ${option_args}
            --templates ${CROSSRT_TEMPLATE_DIR}
            --depfile ${out_dir}/${gen}.d --depfile-target ${first_output}
            --build-dir ${CMAKE_BINARY_DIR} --source-root ${CMAKE_SOURCE_DIR}
            "$<$<BOOL:${CROSSRT_REMOTE_STORAGE}>:--remote-storage;${CROSSRT_REMOTE_STORAGE}>"
            "$<$<BOOL:${CROSSRT_REMOTE_KEY_FILE}>:--remote-key-file;${CROSSRT_REMOTE_KEY_FILE}>"
            -- ${compile_args}
    DEPENDS ${abs_sources} ${candidates} ${translator_dep}
    DEPFILE ${out_dir}/${gen}.d
    COMMENT "CrossRT: translating ${class} -> ${gen}"
    COMMAND_EXPAND_LISTS
    VERBATIM)

  # `cmake --build . --target crossrt_generate` translates every class without compiling anything.
  if(NOT TARGET crossrt_generate)
    add_custom_target(crossrt_generate)
  endif()
  add_custom_target(crossrt_generate_${target}_${gen} DEPENDS ${outputs})
  add_dependencies(crossrt_generate crossrt_generate_${target}_${gen})

  target_sources(${target} PRIVATE ${outputs})
  target_include_directories(${target} PRIVATE ${out_dir})
  if(suffix STREQUAL "ISPC")
    # The kernels, compiled for every target in CROSSRT_ISPC_TARGETS with ISPC's run-time dispatch:
    # one object per target and the dispatcher, and the header the generated class includes.
    # Without fused multiply-adds, as the C++ and the Vulkan shaders compute (NoContraction); the
    # fma() a kernel calls is LLVM's, exact as C++'s std::fma (--enable-llvm-intrinsics).
    set(ispc_object ${out_dir}/${gen}_kernels${CMAKE_CXX_OUTPUT_EXTENSION})
    set(ispc_header ${out_dir}/${gen}_kernels_ispc.h)
    set(ispc_objects ${ispc_object})
    foreach(t IN LISTS CROSSRT_ISPC_TARGETS)
      string(REGEX REPLACE "-.*$" "" isa "${t}")
      list(APPEND ispc_objects ${out_dir}/${gen}_kernels_${isa}${CMAKE_CXX_OUTPUT_EXTENSION})
    endforeach()
    string(REPLACE ";" "," ispc_targets "${CROSSRT_ISPC_TARGETS}")
    set(runtime_inc "$<TARGET_PROPERTY:crossrt::cpu_runtime,INTERFACE_INCLUDE_DIRECTORIES>")
    add_custom_command(
      OUTPUT ${ispc_objects} ${ispc_header}
      COMMAND ${CROSSRT_ISPC_EXECUTABLE} ${ispc_source} -o ${ispc_object} -h ${ispc_header}
              --target=${ispc_targets} -O2 --pic --wno-perf --opt=disable-fma --enable-llvm-intrinsics
              "$<$<BOOL:${CROSSRT_ISPC_WERROR}>:--werror>"
              "$<$<BOOL:${runtime_inc}>:-I$<JOIN:${runtime_inc},$<SEMICOLON>-I>>"
              -M -MF ${ispc_object}.d -MT ${ispc_object}
      DEPENDS ${ispc_source}
      DEPFILE ${ispc_object}.d
      COMMENT "CrossRT: compiling ${gen}_kernels.ispc for ${ispc_targets}"
      COMMAND_EXPAND_LISTS
      VERBATIM)
    get_target_property(target_type ${target} TYPE)
    if(target_type STREQUAL "OBJECT_LIBRARY")
      # An object library does not hand compiled objects it did not compile on: its users link them.
      target_sources(${target} PRIVATE ${ispc_header})
      target_link_libraries(${target} INTERFACE ${ispc_objects})
    else()
      target_sources(${target} PRIVATE ${ispc_objects} ${ispc_header})
    endif()
  endif()
  get_target_property(linked_type ${target} TYPE)
  if(suffix STREQUAL "Vulkan")
    target_link_libraries(${target} PRIVATE crossrt::runtime)
  elseif(linked_type MATCHES "^(STATIC|OBJECT)_LIBRARY$")
    # The executables that link a static library of CPU classes get the runtime's usage
    # requirements too: passive OpenMP waits (src/OpenMPWaits.cpp of the runtime).
    target_link_libraries(${target} PUBLIC crossrt::cpu_runtime)
  else()
    target_link_libraries(${target} PRIVATE crossrt::cpu_runtime)
  endif()
  if(NOT suffix STREQUAL "Vulkan" AND CROSSRT_LIBRARY_DIR AND linked_type MATCHES "^(EXECUTABLE|SHARED_LIBRARY|MODULE_LIBRARY)$"
     AND NOT CROSSRT_LIBRARY_DIR IN_LIST CMAKE_CXX_IMPLICIT_LINK_DIRECTORIES)
    # An installed CrossRT outside the system's library folders: the target, once installed, finds
    # libcrossrt_openmp_waits.so there (CMake's build-tree RPATH finds it before that). A program
    # that links a static library of CPU classes sets its own INSTALL_RPATH.
    get_target_property(install_rpath ${target} INSTALL_RPATH)
    if(NOT CROSSRT_LIBRARY_DIR IN_LIST install_rpath)
      set_property(TARGET ${target} APPEND PROPERTY INSTALL_RPATH "${CROSSRT_LIBRARY_DIR}")
    endif()
  endif()
  target_link_libraries(${target} PRIVATE crossrt::litemath)
  # The size annotation is for the translator; compilers need not warn about it.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12)
    target_compile_options(${target} PRIVATE -Wno-attributes=crossrt::size)
  elseif(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    target_compile_options(${target} PRIVATE -Wno-unknown-attributes)
  endif()
endfunction()
