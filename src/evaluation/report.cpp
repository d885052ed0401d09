// `shadowbake report`'s outputs: the report's data (report_data.h) rendered as report.json
// (report_json.h) and index.html (report_page.h), published with the images they refer to.
#include "evaluation/report.h"

#include "evaluation/report_json.h"
#include "evaluation/report_page.h"

namespace sb {

Status write_report(const Scene& scene, const std::vector<MethodRun>& runs,
                    const MethodRun& reference, OutputFolder& folder) {
  auto data = compute_report_data(scene, runs, reference, folder);
  if (!data) return data.error();
  // Every file appears together, or none does.
  if (auto s = write_text_file(folder.staged("report.json"), report_json(*data, folder.dir())); !s)
    return s;
  if (auto s = write_text_file(folder.staged("index.html"), report_page(*data)); !s) return s;
  std::vector<std::string> written = std::move(data->images);
  written.push_back("report.json");
  written.push_back("index.html");
  return folder.publish(written);
}

}  // namespace sb
