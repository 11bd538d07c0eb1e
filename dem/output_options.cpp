// The keywords of fix fdm/output (output_options.h).
#include "output_options.h"

namespace fdm {

OutputOptions parseOutputOptions(const std::vector<std::string> &args)
{
  OutputOptions o;
  KeywordTable table("fix fdm/output");
  // "records N FILE" and "vtk M DIR": every N (M) steps, to FILE (into DIR)
  auto every = [&table](const std::string &key, long long &n, std::string &path) {
    return [&table, key, &n, &path](const std::string *v) {
      n = table.toInteger(key, v[0]);
      if (n < 1) table.fail(key + " every " + v[0] + " steps: must be 1 or more");
      path = v[1];
    };
  };
  table.values("records", 2, every("records", o.recordEvery, o.recordPath))
      .values("vtk", 2, every("vtk", o.vtkEvery, o.vtkDir))
      .yesNo("append", o.append);
  table.parse(args, "records N FILE, vtk M DIR, append yes|no; docs/commands/fix_fdm_output.md");
  if (!o.recordEvery && !o.vtkEvery) table.fail("nothing to write: give records N FILE and/or vtk M DIR");
  return o;
}

}  // namespace fdm
