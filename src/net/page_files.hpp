#pragma once
// The Onika page's files (onika/ in the source tree), embedded in the program at build time by
// src/net/embed_page.cmake: nothing is read from disk or fetched from elsewhere when it runs.

#include <string_view>

namespace chimera::net {

struct PageFile {
  std::string_view path;          // "/static/js/canvas.js"
  std::string_view content_type;  // "text/javascript; charset=utf-8"
  std::string_view body;
};

/// The file served at `path` ("/" and "/index.html" are /static/index.html); nullptr if none.
const PageFile* find_page_file(std::string_view path);

}  // namespace chimera::net
