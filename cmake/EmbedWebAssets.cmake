# Bundles the HTML report's web assets into a library target (README "Reports").
#
# The charting library (uPlot, pinned in web/package.json and web/package-lock.json) comes from
# the npm registry: at configure time `npm ci` installs it into a copy of web/ in the build tree
# (the source tree is never written), once per package-lock.json (a stamp file records its hash,
# so reconfiguring and rebuilding do not download again; npm's own cache serves fresh build
# trees). Then the library's minified JavaScript, its CSS and license, and servotwin's glue
# (web/src/report.js, web/src/report.css) are written as byte arrays into a generated C++ file
# compiled into the target, so every report embeds them and opens offline.
#
#   servotwin_embed_web_assets(<target>)
#
# Needs npm (Debian package npm; scripts/install-deps.sh installs it) and, the first time, the npm
# registry or a filled npm cache. SERVOTWIN_NPM names the npm executable when it is not on PATH.

set(SERVOTWIN_WEB_SOURCE_DIR ${PROJECT_SOURCE_DIR}/web)

# Fails configuration when `text` contains a sequence that would end or confuse the HTML element
# the asset is inlined in (<script> or <style>).
function(_servotwin_check_inline_safe path kind)
  file(READ ${path} text)
  string(TOLOWER "${text}" lower)
  if(kind STREQUAL "script")
    set(forbidden "</script" "<!--" "<script")
  else()
    set(forbidden "</style")
  endif()
  foreach(seq IN LISTS forbidden)
    string(FIND "${lower}" "${seq}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${path} contains '${seq}' at byte ${at}: it cannot be inlined in a <${kind}> element of "
                          "the HTML report. Use a different version of the library or change the glue code.")
    endif()
  endforeach()
endfunction()

# Appends `name` as a constexpr byte array with the contents of `path` to the variable `out`.
function(_servotwin_append_byte_array out name path)
  file(READ ${path} hex HEX)
  string(LENGTH "${hex}" hex_length)
  math(EXPR size "${hex_length} / 2")
  string(REPEAT "[0-9a-f][0-9a-f]" 32 line_pattern)
  string(REGEX REPLACE "(${line_pattern})" "\\1\n" hex "${hex}")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  file(RELATIVE_PATH shown ${PROJECT_BINARY_DIR} ${path})
  set(${out} "${${out}}\n// ${shown}\nconstexpr unsigned char ${name}[${size}] = {\n${bytes}};\n" PARENT_SCOPE)
endfunction()

function(servotwin_embed_web_assets target)
  find_program(SERVOTWIN_NPM npm DOC "npm, used to install the report's charting library at configure time")
  if(NOT SERVOTWIN_NPM)
    message(FATAL_ERROR
      "npm was not found. servotwin's HTML reports embed the uPlot charting library, which the build installs "
      "from the npm registry with npm. Install npm (on Debian: scripts/install-deps.sh, or apt-get install npm) "
      "or set SERVOTWIN_NPM to the npm executable, then configure again.")
  endif()

  set(package_json ${SERVOTWIN_WEB_SOURCE_DIR}/package.json)
  set(package_lock ${SERVOTWIN_WEB_SOURCE_DIR}/package-lock.json)
  set(glue_js ${SERVOTWIN_WEB_SOURCE_DIR}/src/report.js)
  set(glue_css ${SERVOTWIN_WEB_SOURCE_DIR}/src/report.css)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${package_json} ${package_lock} ${glue_js} ${glue_css})

  file(READ ${package_json} manifest)
  string(JSON pinned ERROR_VARIABLE json_error GET "${manifest}" dependencies uplot)
  if(json_error OR NOT pinned MATCHES "^[0-9]+\\.[0-9]+\\.[0-9]+$")
    message(FATAL_ERROR "${package_json}: dependencies.uplot must pin an exact version (x.y.z), got '${pinned}'")
  endif()

  # npm ci into a build-tree copy of web/, once per package-lock.json.
  set(web_build ${PROJECT_BINARY_DIR}/web)
  set(stamp ${web_build}/node_modules/.servotwin-package-lock.sha256)
  set(dist ${web_build}/node_modules/uplot/dist)
  file(SHA256 ${package_lock} lock_hash)
  set(installed_hash "")
  if(EXISTS ${stamp})
    file(READ ${stamp} installed_hash)
  endif()
  if(NOT installed_hash STREQUAL lock_hash OR NOT EXISTS ${dist}/uPlot.iife.min.js)
    file(MAKE_DIRECTORY ${web_build})
    configure_file(${package_json} ${web_build}/package.json COPYONLY)
    configure_file(${package_lock} ${web_build}/package-lock.json COPYONLY)
    message(STATUS "Installing uplot@${pinned} for the HTML report (npm ci in ${web_build})")
    execute_process(
      COMMAND ${SERVOTWIN_NPM} ci --ignore-scripts --no-audit --no-fund --prefer-offline --loglevel=error
      WORKING_DIRECTORY ${web_build}
      RESULT_VARIABLE npm_result
      OUTPUT_VARIABLE npm_output
      ERROR_VARIABLE npm_output
      TIMEOUT 900)
    if(NOT npm_result EQUAL 0)
      message(FATAL_ERROR
        "`npm ci` failed (${npm_result}) in ${web_build}:\n${npm_output}\n"
        "The build installs uplot@${pinned}, the charting library embedded in HTML reports, from the npm registry "
        "(once; later builds use npm's cache). Check the network and npm's registry setting "
        "(`npm config get registry`), then configure again.")
    endif()
    file(WRITE ${stamp} "${lock_hash}")
  endif()

  file(READ ${web_build}/node_modules/uplot/package.json installed_manifest)
  string(JSON installed_version GET "${installed_manifest}" version)
  if(NOT installed_version STREQUAL pinned)
    message(FATAL_ERROR "npm installed uplot ${installed_version} but web/package.json pins ${pinned}: "
                        "regenerate web/package-lock.json (npm install --package-lock-only in a copy of web/)")
  endif()

  set(uplot_js ${dist}/uPlot.iife.min.js)
  set(uplot_css ${dist}/uPlot.min.css)
  set(uplot_license ${web_build}/node_modules/uplot/LICENSE)
  _servotwin_check_inline_safe(${uplot_js} script)
  _servotwin_check_inline_safe(${glue_js} script)
  _servotwin_check_inline_safe(${uplot_css} style)
  _servotwin_check_inline_safe(${glue_css} style)
  file(READ ${uplot_license} license_text)
  string(FIND "${license_text}" "*/" comment_end)
  if(NOT comment_end EQUAL -1)
    message(FATAL_ERROR "${uplot_license} contains '*/' and cannot be embedded in a JavaScript comment")
  endif()

  set(arrays "")
  _servotwin_append_byte_array(arrays kUplotJs ${uplot_js})
  _servotwin_append_byte_array(arrays kUplotCss ${uplot_css})
  _servotwin_append_byte_array(arrays kUplotLicense ${uplot_license})
  _servotwin_append_byte_array(arrays kGlueJs ${glue_js})
  _servotwin_append_byte_array(arrays kGlueCss ${glue_css})

  set(generated ${PROJECT_BINARY_DIR}/generated/report/web_assets.cpp)
  file(WRITE ${generated}.tmp
"// Generated by cmake/EmbedWebAssets.cmake from web/ and uplot@${pinned} (npm); do not edit.
#include \"${PROJECT_SOURCE_DIR}/src/report/web_assets.hpp\"

namespace servotwin::report::detail {
namespace {
${arrays}
std::string_view view(const unsigned char* bytes, std::size_t size) {
  return {reinterpret_cast<const char*>(bytes), size};
}
}  // namespace

WebAssets web_assets() {
  WebAssets a;
  a.chart_library_name = \"uPlot\";
  a.chart_library_version = \"${pinned}\";
  a.chart_library_js = view(kUplotJs, sizeof kUplotJs);
  a.chart_library_css = view(kUplotCss, sizeof kUplotCss);
  a.chart_library_license = view(kUplotLicense, sizeof kUplotLicense);
  a.glue_js = view(kGlueJs, sizeof kGlueJs);
  a.glue_css = view(kGlueCss, sizeof kGlueCss);
  return a;
}

}  // namespace servotwin::report::detail
")
  # Replace the file only when its content changed, so a reconfigure does not force a rebuild.
  configure_file(${generated}.tmp ${generated} COPYONLY)
  file(REMOVE ${generated}.tmp)
  target_sources(${target} PRIVATE ${generated})
endfunction()
