/* The keywords of fix fdm/output (docs/commands/fix_fdm_output.md), parsed by one keyword table
   (keyword_table.h): every message starts with the fix's name and names the keyword and the value it got.
   No LIGGGHTS: the fix hands its arguments after "fix ID all fdm/output" and turns a KeywordError into
   error->all. */

#ifndef FDM_OUTPUT_OPTIONS_H
#define FDM_OUTPUT_OPTIONS_H

#include "keyword_table.h"

#include <string>
#include <vector>

namespace fdm {

struct OutputOptions {
  long long recordEvery = 0;   // records N FILE (0: none)
  std::string recordPath;
  long long vtkEvery = 0;      // vtk M DIR (0: none)
  std::string vtkDir;
  bool append = false;         // append yes: continue an existing records file
};

// The options of `args`, or KeywordError naming the first problem (N or M below 1, nothing to write).
OutputOptions parseOutputOptions(const std::vector<std::string> &args);

}  // namespace fdm

#endif
