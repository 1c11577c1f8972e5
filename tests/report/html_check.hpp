#pragma once
// Test helper: a strict-enough HTML well-formedness check (every non-void element closed, in order).
#include <algorithm>
#include <string>
#include <vector>

namespace varslam::report::testing {

/// Empty when the tags balance; otherwise a description of the first problem.
inline std::string html_tag_balance_problem(const std::string& html) {
  static const std::vector<std::string> kVoid = {"meta", "img", "br", "hr", "input", "link", "area", "base", "col",
                                                 "embed", "source", "track", "wbr"};
  std::vector<std::string> stack;
  std::size_t pos = 0;
  while ((pos = html.find('<', pos)) != std::string::npos) {
    if (html.compare(pos, 4, "<!--") == 0) {
      pos = html.find("-->", pos);
      if (pos == std::string::npos) return "unterminated comment";
      continue;
    }
    const std::size_t end = html.find('>', pos);
    if (end == std::string::npos) return "unterminated tag at " + std::to_string(pos);
    std::string tag = html.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.empty() || tag[0] == '!' || tag[0] == '?') continue;  // doctype, processing instruction
    const bool closing = tag[0] == '/';
    const bool self_closed = tag.back() == '/';
    std::string name = tag.substr(closing ? 1 : 0);
    name = name.substr(0, name.find_first_of(" \t\n/"));
    if (name.empty()) return "empty tag name";
    if (closing) {
      if (stack.empty() || stack.back() != name)
        return "</" + name + "> closes <" + (stack.empty() ? std::string("nothing") : stack.back()) + ">";
      stack.pop_back();
    } else if (!self_closed && std::find(kVoid.begin(), kVoid.end(), name) == kVoid.end()) {
      stack.push_back(name);
      // Raw text elements: skip to their end tag.
      if (name == "style" || name == "script") {
        const std::size_t close = html.find("</" + name + ">", pos);
        if (close == std::string::npos) return "unclosed <" + name + ">";
        pos = close;
      }
    }
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + ">";
  return {};
}

}  // namespace varslam::report::testing
