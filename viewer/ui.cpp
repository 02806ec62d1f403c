// ui.cpp — see ui.h.
#include "viewer/ui.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

#include "viewer/montage_panel.h"

namespace ossa::view {
namespace {

void smooth(double& into, double value) { into += 0.05 * (value - into); }

/// The rows of controls under the clip list (play / loop, time, speed, cross-fade): what the list
/// leaves room for when it fills the section.
constexpr float kClipControlRows = 4.0f;

void clips_panel(App& app, UiState& ui, float* hidden) {
  Playback& p = app.animator.playback;
  const float below = kClipControlRows * ImGui::GetFrameHeightWithSpacing();
  if (app.scene.clips.empty()) {
    ImGui::TextDisabled("no clips: drop clip files cooked for this skeleton");
  } else if (ImGui::BeginListBox(
                 "##clips",
                 ImVec2(-1.0f, fill_list_height(static_cast<float>(app.scene.clips.size()) + 0.5f, below, hidden)))) {
    for (size_t i = 0; i < app.scene.clips.size(); ++i) {
      const SceneClip& c = app.scene.clips[i];
      ImGui::PushID(static_cast<int>(i));
      if (ImGui::Selectable(c.label.c_str(), p.clip == static_cast<int>(i))) {
        if (Status s = play_clip(app, static_cast<int>(i), true); !s) ui.status = s.message();
      }
      ImGui::PopID();
    }
    ImGui::EndListBox();
  }
  if (ImGui::Button(p.playing ? "Pause" : "Play")) p.playing = !p.playing;
  ImGui::SameLine();
  ImGui::Checkbox("loop", &p.loop);
  ImGui::SameLine();
  ImGui::Checkbox("bind pose", &p.bind_pose);
  const float duration = clip_duration(app.scene, app.animator);
  float t = p.time;
  if (ImGui::SliderFloat("time", &t, 0.0f, std::max(duration, 1e-3f), "%.3f s")) set_time(app.scene, app.animator, t);
  ImGui::SliderFloat("speed", &p.speed, -2.0f, 2.0f, "%.2fx");
  ImGui::SliderFloat("cross-fade", &p.fade_seconds, 0.0f, 1.0f, "%.2f s");
}

/// The retarget mode (retarget_view.h): the source's clips (the one picked drives the character),
/// the source and mapping toggles, and a way back to the character's own clips.
void retarget_panel(App& app, UiState& ui, float aspect, float* hidden) {
  RetargetView& v = *app.retarget;
  ImGui::TextWrapped("source: %s", std::filesystem::path(v.files.front()).filename().string().c_str());
  if (!v.map_file.empty()) ImGui::TextWrapped("map: %s", std::filesystem::path(v.map_file).filename().string().c_str());
  const Playback& p = v.animator.playback;
  const float below = 3.0f * ImGui::GetFrameHeightWithSpacing();  // the line, the toggles and the button under it
  if (ImGui::BeginListBox(
          "##retarget-clips",
          ImVec2(-1.0f, fill_list_height(static_cast<float>(v.source.clips.size()) + 0.5f, below, hidden)))) {
    for (size_t i = 0; i < v.source.clips.size(); ++i) {
      ImGui::PushID(static_cast<int>(i));
      if (ImGui::Selectable(v.source.clips[i].label.c_str(), p.clip == static_cast<int>(i))) {
        if (Status s = select_clip(v.source, v.animator, static_cast<int>(i), true); !s) ui.status = s.message();
      }
      ImGui::PopID();
    }
    ImGui::EndListBox();
  }
  ImGui::Text("source clip %.2f s, hips scale %.3f", v.animator.playback.time, v.map.scale);
  ImGui::Checkbox("show source", &v.show_source);
  ImGui::SameLine();
  ImGui::Checkbox("show mapping", &app.toggles.mapping);
  if (ImGui::Button("stop retargeting")) {
    if (Status s = set_retarget(app, {}, {}, {}, aspect); !s) ui.status = s.message();
  }
}

/// One slider per morph channel. A channel left to the clip shows instance 0's live weight (the
/// slider moves as the clip plays); moving the slider, or ticking its box, holds the channel at
/// the slider's value; unticking gives it back to the clip.
void morph_panel(App& app) {
  Animator& a = app.animator;
  MorphOverrides& o = a.morph_overrides;
  const std::vector<float>& live = a.instances.front().morph_weights;
  for (size_t c = 0; c < app.scene.morph_channels.size() && c < o.held.size() && c < live.size(); ++c) {
    const std::string name(app.scene.morph_channels[c]);
    ImGui::PushID(static_cast<int>(c));
    bool held = o.held[c] != 0;
    if (ImGui::Checkbox("##hold", &held)) hold_morph(a, c, held, held ? live[c] : o.value[c]);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("hold this weight (unticked: the clip drives it)");
    ImGui::SameLine();
    float w = held ? o.value[c] : live[c];
    if (ImGui::SliderFloat(name.c_str(), &w, 0.0f, 1.0f, held ? "%.3f (held)" : "%.3f")) hold_morph(a, c, true, w);
    ImGui::PopID();
  }
  if (ImGui::Button("release all")) {
    for (size_t c = 0; c < o.held.size(); ++c) hold_morph(a, c, false, o.value[c]);
  }
  ImGui::SameLine();
  ImGui::TextDisabled("ctrl+click a slider to type a weight");
}

void cloth_panel(App& app);

/// The character's motion through the world (animation.h Drive, --move / --turn): a speed along
/// its front and a turn rate, as a game moves a character playing an in-place clip; the cloth
/// feels both. "back to the start" puts it where it began.
void drive_panel(App& app) {
  Drive& d = app.animator.drive;
  if (app.scene.assets.empty()) return;
  const float metres = std::max(app.scene.character().file().metres_per_unit(), 1e-6f);
  float move = d.speed * metres, turn = d.turn_rate * 57.29578f;
  if (ImGui::SliderFloat("move m/s", &move, -8.0f, 8.0f, "%.1f")) d.speed = move / metres;
  if (ImGui::SliderFloat("turn deg/s", &turn, -180.0f, 180.0f, "%.0f")) {
    d.turn_rate = turn / 57.29578f;
    d.turn_after = std::min(d.turn_after, d.clock);  // from now on
  }
  if (d.active() || d.clock > 0.0f) {
    if (ImGui::Button("back to the start")) {
      d.clock = d.heading = 0.0f;
      d.position = glm::vec3(0.0f);
      d.world = glm::mat4(1.0f);
      d.speed = d.turn_rate = 0.0f;
      reset_viewer_cloth(app.cloth);
    }
  }
}

void view_panel(App& app, UiState& ui, float aspect) {
  ImGui::Checkbox("skeleton (K)", &app.toggles.skeleton);
  ImGui::SameLine();
  ImGui::Checkbox("wireframe (F)", &app.toggles.wireframe);
  ImGui::Checkbox("grid (G)", &app.toggles.grid);
  ImGui::SameLine();
  ImGui::Checkbox("CPU skinning", &app.toggles.cpu_skinning);
  cloth_panel(app);
  ImGui::Checkbox("follow character", &app.follow);
  ImGui::SameLine();
  if (ImGui::Button("frame (R)")) frame_camera(app, aspect);
  drive_panel(app);
  int crowd = static_cast<int>(app.crowd);
  if (ImGui::SliderInt("crowd", &crowd, 1, 256) && crowd != static_cast<int>(app.crowd)) {
    if (Status s = set_crowd(app, static_cast<size_t>(crowd), aspect); !s) ui.status = s.message();
  }
}

const char* node_kind(const fb::Node& n) { return fb::EnumNameNodeData(n.data_type()); }

void graph_parameters(GraphDriver& g, UiState& ui) {
  const GraphDefinition& d = *g.definition;
  const GraphInstance& first = g.instances.front();
  for (size_t i = 0; i < d.parameter_count(); ++i) {
    const int p = static_cast<int>(i);
    const fb::Parameter& param = *d.graph().parameters()->Get(static_cast<flatbuffers::uoffset_t>(i));
    const std::string label = std::string(d.parameter_name(i));
    const float lo = param.min_value(), hi = param.max_value();
    const bool bounded = lo > -1e6f && hi < 1e6f && lo < hi;
    float v = first.value(p);
    switch (d.parameter_type(i)) {
      case fb::ParameterType::Float: {
        const bool changed =
            bounded ? ImGui::SliderFloat(label.c_str(), &v, lo, hi) : ImGui::DragFloat(label.c_str(), &v, 0.01f);
        if (changed) {
          set_graph_value(g, p, v);
          if (label == "speed") ui.graph_slider_touched = true;
        }
        break;
      }
      case fb::ParameterType::Int: {
        int n = static_cast<int>(v);
        const bool changed = bounded ? ImGui::SliderInt(label.c_str(), &n, static_cast<int>(lo), static_cast<int>(hi))
                                     : ImGui::DragInt(label.c_str(), &n);
        if (changed) set_graph_value(g, p, static_cast<float>(n));
        break;
      }
      case fb::ParameterType::Bool: {
        bool b = v != 0.0f;
        if (ImGui::Checkbox(label.c_str(), &b)) set_graph_value(g, p, b ? 1.0f : 0.0f);
        break;
      }
      case fb::ParameterType::Enum: {
        std::vector<const char*> names;
        if (param.enum_values() != nullptr) {
          for (const flatbuffers::String* e : *param.enum_values()) names.push_back(e->c_str());
        }
        int n = static_cast<int>(v);
        if (!names.empty() && ImGui::Combo(label.c_str(), &n, names.data(), static_cast<int>(names.size()))) {
          set_graph_value(g, p, static_cast<float>(n));
        }
        break;
      }
      case fb::ParameterType::Trigger:
        if (ImGui::Button(label.c_str())) fire_graph_trigger(g, p);
        ImGui::SameLine();
        ImGui::TextDisabled(v != 0.0f ? "(trigger, set)" : "(trigger)");
        break;
      case fb::ParameterType::Vector: {
        glm::vec3 x = first.vector(p);
        if (ImGui::DragFloat3(label.c_str(), &x.x, 0.01f)) (void)set_graph_vector(g, p, x);
        break;
      }
    }
  }
}

void graph_status(const GraphDriver& g) {
  const GraphDefinition& d = *g.definition;
  const GraphInstance& first = g.instances.front();
  for (size_t m = 0; m < d.machine_count(); ++m) {
    const MachineStatus st = first.machine_status(m);
    const auto state = [&](int s) {
      return s >= 0 ? std::string(d.state_name(m, static_cast<size_t>(s))) : std::string("-");
    };
    ImGui::Text("%.*s: %s", static_cast<int>(d.machine_name(m).size()), d.machine_name(m).data(),
                state(st.current).c_str());
    if (st.previous >= 0) {
      ImGui::Text("  from %s  %.2f / %.2f s", state(st.previous).c_str(), st.elapsed, st.duration);
      ImGui::ProgressBar(st.weight, ImVec2(-1.0f, 0.0f), "transition weight");
    }
    if (st.inertial_remaining > 0.0f) ImGui::Text("  inertializing: %.2f s left", st.inertial_remaining);
  }
  ImGui::TextDisabled("nodes with weight");
  for (size_t n = 0; n < d.node_count(); ++n) {
    const float w = first.node_weight(n);
    if (w <= 0.0f) continue;
    const fb::Node& node = *d.graph().nodes()->Get(static_cast<flatbuffers::uoffset_t>(n));
    char overlay[96];
    std::snprintf(overlay, sizeof overlay, "%s (%s) %.2f",
                  node.name() && node.name()->size() ? node.name()->c_str() : "-", node_kind(node), w);
    ImGui::ProgressBar(w, ImVec2(-1.0f, 0.0f), overlay);
  }
  ImGui::TextDisabled("events");
  for (const std::string& e : g.recent_events) ImGui::TextUnformatted(e.c_str());
}

/// The cloth's controls (cloth_view.h), when the character has cloth: on / off, the overlay,
/// wind (metres per second along the view's x and z), stiffness and a restart from the skinned pose.
void cloth_panel(App& app) {
  if (app.cloth.empty()) return;
  ImGui::Separator();
  ImGui::TextDisabled("cloth (%zu simulated)", app.cloth.sims.size());
  ImGui::Checkbox("simulate cloth", &app.cloth.enabled);
  ImGui::SameLine();
  ImGui::Checkbox("show particles", &app.show_cloth);
  ImGui::SliderFloat3("wind m/s", &app.cloth.wind.x, -15.0f, 15.0f, "%.1f");
  ImGui::SliderFloat("stiffness", &app.cloth.stiffness, 0.05f, 1.0f, "%.2f");
  if (ImGui::Button("reset cloth")) reset_viewer_cloth(app.cloth);
}

/// The procedural nodes' controls: the overlay toggle, the targets (dragged in the view with
/// Ctrl + left-drag, or a left-drag that starts on a marker), and, with foot placement, the
/// ground: a tilt about the character's x axis (sets every leg's normal parameter) and a height
/// per foot (the legs' ground parameters).
void procedural_panel(App& app) {
  GraphDriver& g = *app.animator.graph;
  const ProceduralInfo& info = g.procedural;
  if (info.empty()) return;
  const GraphDefinition& d = *g.definition;
  const GraphInstance& first = g.instances.front();
  ImGui::Separator();
  ImGui::TextDisabled("procedural");
  ImGui::Checkbox("show procedural", &app.toggles.procedural);
  for (const TargetHandle& h : info.targets) {
    const glm::vec3 v = first.vector(h.parameter);
    const bool reached = !h.pole && h.node >= 0 && first.reached(static_cast<size_t>(h.node));
    ImGui::Text("%s %s (%.1f %.1f %.1f)%s", h.pole ? "pole" : "target", h.name.c_str(), v.x, v.y, v.z,
                h.pole    ? ""
                : reached ? "  reached"
                          : "  not reached");
  }
  if (!info.targets.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("drag a marker (ctrl+drag: the nearest one) to move it in the view plane");
    ImGui::PopStyleColor();
  }
  if (info.legs.empty()) return;
  const float size = app.bind_box.empty() ? 1.0f : app.bind_box.size().y;
  int normal = -1;
  for (const FootLegInfo& leg : info.legs) normal = normal >= 0 ? normal : leg.normal;
  if (normal >= 0) {
    float tilt = tilt_degrees(first.vector(normal));
    if (ImGui::SliderFloat("ground tilt", &tilt, -25.0f, 25.0f, "%.1f deg")) {
      for (const FootLegInfo& leg : info.legs)
        if (leg.normal >= 0) (void)set_graph_vector(g, leg.normal, tilted_normal(tilt));
    }
  }
  for (const FootLegInfo& leg : info.legs) {
    if (leg.ground < 0) continue;
    const fb::Parameter& param = *d.graph().parameters()->Get(static_cast<flatbuffers::uoffset_t>(leg.ground));
    const bool bounded = param.min_value() > -1e6f && param.max_value() < 1e6f && param.min_value() < param.max_value();
    const float lo = bounded ? param.min_value() : -0.3f * size, hi = bounded ? param.max_value() : 0.3f * size;
    float h = first.value(leg.ground);
    ImGui::PushID(leg.ground);
    if (ImGui::SliderFloat(leg.left ? "ground height left" : "ground height right", &h, lo, hi, "%.2f"))
      set_graph_value(g, leg.ground, h);
    ImGui::PopID();
  }
}

void graph_panel(App& app, UiState& ui) {
  Animator& a = app.animator;
  if (!a.graph) {
    bool any = false;
    for (const Asset& asset : app.scene.assets) {
      const auto* graphs = asset.file().graphs();
      if (graphs == nullptr) continue;
      for (const fb::Graph* g : *graphs) {
        any = true;
        if (ImGui::Button(("play graph '" + g->name()->str() + "'").c_str())) {
          if (Status s = use_graph(app, g->name()->str()); !s) ui.status = s.message();
        }
      }
    }
    if (!any) ImGui::TextDisabled("no graph in the files opened (open one with --graph NAME)");
    return;
  }
  ImGui::Checkbox("graph drives the character", &a.use_graph);
  if (a.graph->instances.empty()) return;
  ImGui::Text("graph '%s'", a.graph->name.c_str());
  graph_parameters(*a.graph, ui);
  procedural_panel(app);
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
  ImGui::TextWrapped("keys: W walk, Shift+W run (release to stop), C crossed arms, M montage");
  ImGui::PopStyleColor();
  montage_panel(*a.graph);
  graph_status(*a.graph);
}

void stats_panel(const App& app, const UiState& ui) {
  const SceneCounts c = count(app.scene);
  ImGui::Text("joints %zu   meshes %zu   instances %zu", c.joints, c.meshes, app.crowd);
  ImGui::Text("vertices %zu   triangles %zu", c.vertices * app.crowd, c.triangles * app.crowd);
  const FrameTimings& t = ui.smoothed;
  ImGui::Text("frame %.2f ms (%.0f fps)", ui.frame_ms, ui.frame_ms > 0 ? 1000.0 / ui.frame_ms : 0.0);
  ImGui::Text("sample %.3f  blend %.3f  skin %.3f ms", t.sample_ms, t.blend_ms, t.skin_ms);
  if (app.animator.graph && app.animator.use_graph)
    ImGui::Text("graph update %.3f ms (sampling and blending)", t.graph_ms);
  ImGui::Text("draw %.3f ms (CPU)   GPU %.3f ms", t.draw_ms, t.gpu_ms);
}

void open_panel(UiState& ui) {
  ImGui::InputText("##path", ui.open_path, sizeof ui.open_path);
  ImGui::SameLine();
  if (ImGui::Button("Open") && ui.open_path[0] != '\0') request_paths(ui.work, {ui.open_path});
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
  ImGui::TextWrapped(
      "a character replaces the scene; clip files add clips; sources (FBX, glTF, ...) are cooked first "
      "(or drop files here)");
  ImGui::PopStyleColor();
}

/// A turning arc: the loading indicator's spinner.
void spinner(ImDrawList* dl, ImVec2 centre, float radius, ImU32 colour) {
  const float start = static_cast<float>(ImGui::GetTime()) * 6.0f;
  dl->PathClear();
  for (int i = 0; i <= 24; ++i) {
    const float a = start + static_cast<float>(i) / 24.0f * 4.5f;
    dl->PathLineTo(ImVec2(centre.x + std::cos(a) * radius, centre.y + std::sin(a) * radius));
  }
  dl->PathStroke(colour, false, std::max(2.0f, radius * 0.25f));
}

/// "loading NAME..." / "cooking NAME  1.2 s" with a spinner, in the middle of the scene.
void loading_indicator(const UiState& ui, const SceneLayout& layout) {
  const auto text = indicator_text(ui.work);
  if (!text) return;
  ImDrawList* dl = ImGui::GetForegroundDrawList();
  const float s = ui.ui_scale, radius = 12.0f * s;
  const ImVec2 size = ImGui::CalcTextSize(text->c_str());
  const float w = size.x + 2.0f * radius + 30.0f * s, h = std::max(size.y, 2.0f * radius) + 20.0f * s;
  const ImVec2 c(layout.scene.x + 0.5f * layout.scene.width, layout.scene.y + 0.5f * layout.scene.height);
  dl->AddRectFilled(ImVec2(c.x - 0.5f * w, c.y - 0.5f * h), ImVec2(c.x + 0.5f * w, c.y + 0.5f * h),
                    IM_COL32(20, 22, 26, 230), 6.0f * s);
  spinner(dl, ImVec2(c.x - 0.5f * w + 10.0f * s + radius, c.y), radius, IM_COL32(120, 170, 240, 255));
  dl->AddText(ImVec2(c.x - 0.5f * w + 20.0f * s + 2.0f * radius, c.y - 0.5f * size.y), IM_COL32(235, 235, 235, 255),
              text->c_str());
}

void files_panel(UiState& ui, float* hidden) {
  if (const auto chosen = browser_panel(ui.browser, hidden)) request_paths(ui.work, {chosen->string()});
}

/// One collapsible section of the panel: its header, and a body drawn into a child region of the
/// height panel_fit.h shares out (the body adds to `*hidden` the list rows it could not show).
struct Section {
  const char* label;
  ImGuiTreeNodeFlags flags;
  std::function<void(float* hidden)> body;
};

/// The labels drawn right of the panel's widgets: the fixed ones, the graph's parameters and the
/// morph channels, whose widest decides how much room every widget leaves (panel_fit.h label_room).
std::vector<std::string> panel_labels(const App& app) {
  std::vector<std::string> labels = {"time",
                                     "speed",
                                     "cross-fade",
                                     "crowd",
                                     "wind m/s",
                                     "stiffness",
                                     "ground tilt",
                                     "ground height left",
                                     "ground height right",
                                     "move m/s",
                                     "turn deg/s"};
  if (app.animator.graph && app.animator.graph->definition) {
    const GraphDefinition& d = *app.animator.graph->definition;
    for (size_t i = 0; i < d.parameter_count(); ++i) labels.emplace_back(d.parameter_name(i));
  }
  for (std::string_view m : app.scene.morph_channels) labels.emplace_back(m);
  return labels;
}

/// The sections between the panel's top button and its help lines, each open one in a region of
/// its share of the height (panel_fit.h); the column scrolls as a whole only when even their
/// minimum heights do not fit.
void draw_sections(UiState& ui, std::span<const Section> sections, float height, float room) {
  const ImGuiStyle& style = ImGui::GetStyle();
  ImGui::BeginChild("##sections", ImVec2(0.0f, height), false);
  std::vector<float> wanted(sections.size(), -1.0f);
  std::vector<bool> open_flags(sections.size(), false);
  float available = ImGui::GetContentRegionAvail().y;
  for (size_t i = 0; i < sections.size(); ++i) {
    for (const SectionFit& f : ui.sections)
      if (f.name == sections[i].label) wanted[i] = f.wanted;
    open_flags[i] = ImGui::TreeNodeBehaviorIsOpen(ImGui::GetID(sections[i].label), sections[i].flags);
    available -= ImGui::GetFrameHeight() + style.ItemSpacing.y + (open_flags[i] ? style.ItemSpacing.y : 0.0f);
  }
  const std::vector<float> share =
      share_heights(std::floor(available), wanted, open_flags, 3.0f * ImGui::GetFrameHeightWithSpacing());
  std::vector<SectionFit> measured;
  for (size_t i = 0; i < sections.size(); ++i) {
    const Section& sec = sections[i];
    if (!ImGui::CollapsingHeader(sec.label, sec.flags)) continue;
    ImGui::BeginChild((std::string(sec.label) + "##body").c_str(), ImVec2(0.0f, std::max(share[i], 1.0f)), false);
    ImGui::PushItemWidth(-room);
    float hidden = 0.0f;
    sec.body(&hidden);
    ImGui::PopItemWidth();
    measured.push_back({sec.label, std::ceil(ImGui::GetCursorPosY() - style.ItemSpacing.y + hidden)});
    audit_current_window(ui.audit, sec.label, true);
    ImGui::EndChild();
  }
  audit_current_window(ui.audit, "sections", true);
  ImGui::EndChild();
  ui.sections = std::move(measured);
}

}  // namespace

void record_frame(UiState& ui, const FrameTimings& f, double frame_ms) {
  smooth(ui.smoothed.sample_ms, f.sample_ms);
  smooth(ui.smoothed.blend_ms, f.blend_ms);
  smooth(ui.smoothed.graph_ms, f.graph_ms);
  smooth(ui.smoothed.skin_ms, f.skin_ms);
  smooth(ui.smoothed.draw_ms, f.draw_ms);
  if (f.gpu_ms > 0.0) smooth(ui.smoothed.gpu_ms, f.gpu_ms);
  smooth(ui.frame_ms, frame_ms);
}

float panel_width(const UiState& ui) { return ui.panel_open ? std::round(380.0f * ui.ui_scale) : 0.0f; }

void draw_panels(App& app, UiState& ui, const SceneLayout& layout) {
  const float aspect = layout.aspect;
  const ImGuiIO& io = ImGui::GetIO();
  ui.graph_slider_touched = false;
  if (!ui.panel_open) {
    ImGui::SetNextWindowPos(ImVec2(6.0f * ui.ui_scale, 6.0f * ui.ui_scale));
    ImGui::Begin("##show-panel", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoMove);
    if (ImGui::Button(">> panel (Tab)")) ui.panel_open = true;
    ImGui::End();
  } else {
    ImGui::SetNextWindowPos(ImVec2(0.0f, 0.0f));
    ImGui::SetNextWindowSize(ImVec2(panel_width(ui), io.DisplaySize.y));
    const std::string title =
        (app.scene.paths.empty() ? std::string("ossa-view")
                                 : std::filesystem::path(app.scene.paths.front()).filename().string()) +
        "###ossa";
    ImGui::Begin(title.c_str(), nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                     ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus |
                     ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse);
    ui.audit = PanelAudit{};
    ui.audit.panel = Rect{0.0f, 0.0f, panel_width(ui), io.DisplaySize.y};
    if (ImGui::SmallButton("<< hide panel (Tab)")) ui.panel_open = false;
    const bool scene = !app.scene.assets.empty();
    std::vector<Section> sections;
    if (scene) {
      const ImGuiTreeNodeFlags open = ImGuiTreeNodeFlags_DefaultOpen;
      sections.push_back({"Graph", app.animator.graph ? open : 0, [&](float*) { graph_panel(app, ui); }});
      sections.push_back(
          {"Clips", app.animator.graph ? 0 : open, [&](float* hidden) { clips_panel(app, ui, hidden); }});
      if (app.retarget)
        sections.push_back({"Retarget", open, [&](float* hidden) { retarget_panel(app, ui, aspect, hidden); }});
      if (!app.scene.morph_channels.empty())
        sections.push_back({"Morph targets", open, [&](float*) { morph_panel(app); }});
      sections.push_back({"View", open, [&](float*) { view_panel(app, ui, aspect); }});
      sections.push_back({"Stats", open, [&](float*) { stats_panel(app, ui); }});
    }
    sections.push_back({"Files", scene && !ui.browser.open_section ? 0 : ImGuiTreeNodeFlags_DefaultOpen,
                        [&](float* hidden) { files_panel(ui, hidden); }});
    sections.push_back({"Open", 0, [&](float*) { open_panel(ui); }});
    // The help and status lines keep their place at the bottom: the sections get what they leave
    // (their height as measured on the previous frame).
    const ImGuiStyle& style = ImGui::GetStyle();
    const float footer = ui.footer_height > 0.0f ? ui.footer_height : 3.0f * ImGui::GetTextLineHeightWithSpacing();
    const float column =
        std::max(ImGui::GetContentRegionAvail().y - footer - style.ItemSpacing.y, ImGui::GetFrameHeight());
    draw_sections(ui, sections, std::floor(column), label_room(panel_labels(app), 0.45f * panel_width(ui)));
    const float footer_top = ImGui::GetCursorPosY();
    if (const auto busy_text = indicator_text(ui.work)) ImGui::TextDisabled("%s", busy_text->c_str());
    if (!ui.status.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.4f, 0.4f, 1.0f));
      ImGui::TextWrapped("%s", ui.status.c_str());
      ImGui::PopStyleColor();
    }
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.8f, 0.3f, 1.0f));
    for (const std::string& m : app.messages) ImGui::TextWrapped("%s", m.c_str());
    ImGui::PopStyleColor();
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("drag: orbit  right-drag: pan  wheel: zoom  ctrl+drag: move a target");
    ImGui::TextWrapped("space: play/pause  B: bind pose  up/down: clip  Tab: panel");
    ImGui::PopStyleColor();
    ui.footer_height = ImGui::GetCursorPosY() - footer_top;
    audit_current_window(ui.audit, "panel", false);
    ImGui::End();
  }
  if (!app.scene.assets.empty()) timeline_panel(app, ui.timeline, layout.timeline, ui.ui_scale);
  if (app.scene.assets.empty() && !indicator_text(ui.work)) {  // an empty window says what to do
    const char* hint =
        "drop an .ossa file here, or a source to cook\n(FBX, glTF, GLB, DAE, BVH, OBJ),\nor pick one in the panel's "
        "Files";
    const ImVec2 size = ImGui::CalcTextSize(hint);
    ImGui::GetForegroundDrawList()->AddText(ImVec2(layout.scene.x + 0.5f * (layout.scene.width - size.x),
                                                   layout.scene.y + 0.5f * (layout.scene.height - size.y)),
                                            IM_COL32(170, 170, 170, 255), hint);
  }
  loading_indicator(ui, layout);
}

}  // namespace ossa::view
