// What the tests of the styles' keyword parsers share (couple_options, subgrid_options, output_options):
// an input line split into words as LIGGGHTS splits it, and the message of the KeywordError a parse raises.
#ifndef FDM_TESTS_KEYWORD_LINES_H
#define FDM_TESTS_KEYWORD_LINES_H

#include "keyword_table.h"

#include <sstream>
#include <string>
#include <vector>

namespace fdm {
namespace testing {

inline std::vector<std::string> words(const std::string &line)
{
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// The message of the KeywordError parse(words(line)) raises ("" if none).
template <class Parse>
std::string keywordProblem(Parse parse, const std::string &line)
{
  try {
    parse(words(line));
  } catch (const KeywordError &e) {
    return e.what();
  }
  return "";
}

}  // namespace testing
}  // namespace fdm

#endif
