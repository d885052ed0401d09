// describe_plan (convolution_plan.h): the hierarchy of triples as the text `shadowbake plan` and
// `bake --explain` print, and the words for the plan's kinds of split and frustum.
#include <cstdio>

#include "methods/convolution/convolution_plan.h"
#include "occluders/light_frusta.h"

namespace sb {

const char* to_string(TripleSplit split) {
  switch (split) {
    case TripleSplit::none:
      return "";
    case TripleSplit::blocker_depth:
      return "blocker depth";
    case TripleSplit::blocker_space:
      return "blocker space";
    case TripleSplit::receiver_depth:
      return "receiver depth";
  }
  return "?";
}

FrameFace cube_frame_face(int face) { return FrameFace(int(FrameFace::cube_pos_x) + face); }

const char* to_string(FrameFace face) {
  switch (face) {
    case FrameFace::central:
      return "";
    case FrameFace::plane:
      return "plane";
    default:
      return cube_face_name(int(face) - int(FrameFace::cube_pos_x));
  }
}

namespace {

void describe_triple(const ConvolutionPlan& plan, int index, int indent, std::string& out) {
  const Triple& t = plan.triples[index];
  std::string line(std::size_t(indent) * 2, ' ');
  line += t.parent < 0 ? "root"
          : t.section  ? "solid section, subtracted"
                       : to_string(plan.triples[t.parent].split);
  char buf[512];
  if (t.empty) {
    std::snprintf(buf, sizeof buf, ": %zu faces, nothing to convolve\n", t.faces.size());
    out += line + buf;
    return;
  }
  std::snprintf(buf, sizeof buf,
                ": %zu faces (%d polygons) at depth %.3f..%.3f m, %lld texels at %.3f..%.3f m; "
                "eps %.2f texels (%.4f m)",
                t.faces.size(), t.polygons, t.blocker_depths.lo, t.blocker_depths.hi,
                static_cast<long long>(t.footprint_texels), t.receiver_depths.lo,
                t.receiver_depths.hi, t.penumbra_error_texels,
                t.config.penumbra_error + t.view_error);
  line += buf;
  if (t.children.empty()) {
    std::snprintf(buf, sizeof buf, "; image %dx%d (FFT %dx%d), cost %.3g%s", t.grid.width,
                  t.grid.height, t.fft_width, t.fft_height, t.cost, t.blurred ? ", BLURRED" : "");
    line += buf;
    if (t.seconds > 0) {
      std::snprintf(buf, sizeof buf, ", %.2f ms", 1e3 * t.seconds);
      line += buf;
    }
  }
  out += line + "\n";
  for (int c : t.children) describe_triple(plan, c, indent + 1, out);
}

}  // namespace

std::string describe_plan(const ConvolutionPlan& plan) {
  std::string out;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "receiver %s: texel %.2f mm, target %.2f texels; %zu leaves, worst eps %.2f "
                "texels, estimated cost %.3g\n",
                plan.receiver.c_str(), 1e3 * plan.texel,
                plan.texel > 0 ? plan.target / plan.texel : 0.0, plan.leaves().size(),
                plan.worst_error_texels(), plan.estimated_cost());
  out += buf;
  for (const PlanFrame& f : plan.frames) {
    const LightPart& lp = plan.light_parts[f.light_part];
    const char* frustum = f.face == FrameFace::central ? ""
                          : f.face == FrameFace::plane ? ", along the receiver plane's normal"
                                                       : ", cube face ";
    const char* face = f.face == FrameFace::plane ? "" : to_string(f.face);
    std::snprintf(buf, sizeof buf,
                  "  light %s (%.1f%% of its power)%s%s: D = (%.3f, %.3f, %.3f), %zu texels, "
                  "%zu group(s)\n",
                  lp.name.c_str(), 100 * lp.fraction, frustum, face, f.frame.axis.x(),
                  f.frame.axis.y(), f.frame.axis.z(), f.texels.size(), f.groups.size());
    out += buf;
    for (int r : f.roots) describe_triple(plan, r, 2, out);
  }
  for (const std::string& w : plan.warnings) out += "  warning: " + w + "\n";
  return out;
}

}  // namespace sb
