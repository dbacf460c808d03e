#pragma once
// The module templates that `chimera new-module` writes out: the files of
// examples/module_template (C++) and examples/c_module_template (C), embedded at build time.

#include <span>
#include <string_view>

namespace chimera::cli {

enum class TemplateLanguage { kCpp, kC };

struct TemplateFile {
  std::string_view name;  // file name inside the template folder
  std::string_view text;  // the module is called my_module (class MyModule) throughout
};

std::span<const TemplateFile> module_template(TemplateLanguage language);

}  // namespace chimera::cli
