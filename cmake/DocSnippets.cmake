# SPDX-License-Identifier: BSD-2-Clause
# The documentation's programs live in its pages, as code blocks a forge's
# Markdown view shows; the build takes them from there.
#   pkm_doc_snippet(<page.md> <name> <out>): writes the fenced code block that
#   follows the page's line "<!-- snippet <name>: ... -->" to <out> (only when
#   it changed, so that an unchanged page rebuilds nothing); an edit of the
#   page re-runs the configuration.
function(pkm_doc_snippet page name out)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${page}")
  file(READ "${page}" text)
  string(FIND "${text}" "<!-- snippet ${name}:" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${page}: no line \"<!-- snippet ${name}: ... -->\" before a code block")
  endif()
  string(SUBSTRING "${text}" ${at} -1 text)
  string(FIND "${text}" "\n```" open)  # the fence's first line ...
  if(open EQUAL -1)
    message(FATAL_ERROR "${page}: no code block after the snippet line of ${name}")
  endif()
  math(EXPR open "${open} + 4")
  string(SUBSTRING "${text}" ${open} -1 text)
  string(FIND "${text}" "\n" eol)  # ... and its info string (the language)
  math(EXPR eol "${eol} + 1")
  string(SUBSTRING "${text}" ${eol} -1 text)
  string(FIND "${text}" "\n```" close)
  if(close EQUAL -1)
    message(FATAL_ERROR "${page}: the code block of ${name} is not closed")
  endif()
  string(SUBSTRING "${text}" 0 ${close} body)
  file(WRITE "${out}.new" "${body}\n")
  configure_file("${out}.new" "${out}" COPYONLY)
  file(REMOVE "${out}.new")
endfunction()
