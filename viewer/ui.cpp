// ui.cpp — see ui.h.
#include "viewer/ui.h"

#include <algorithm>
#include <filesystem>
#include <vector>

#include <imgui.h>

namespace ossa::view {
namespace {

void smooth(double& into, double value) { into += 0.05 * (value - into); }

void clips_panel(App& app, UiState& ui) {
  Playback& p = app.animator.playback;
  if (app.scene.clips.empty()) {
    ImGui::TextDisabled("no clips: drop clip files cooked for this skeleton");
  } else if (ImGui::BeginListBox("##clips", ImVec2(-1.0f, std::min(8.0f, static_cast<float>(app.scene.clips.size()) + 0.5f) *
                                                               ImGui::GetTextLineHeightWithSpacing()))) {
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

void view_panel(App& app, UiState& ui, float aspect) {
  ImGui::Checkbox("skeleton (K)", &app.toggles.skeleton);
  ImGui::SameLine();
  ImGui::Checkbox("wireframe (F)", &app.toggles.wireframe);
  ImGui::Checkbox("grid (G)", &app.toggles.grid);
  ImGui::SameLine();
  ImGui::Checkbox("CPU skinning", &app.toggles.cpu_skinning);
  ImGui::Checkbox("follow character", &app.follow);
  ImGui::SameLine();
  if (ImGui::Button("frame (R)")) frame_camera(app, aspect);
  int crowd = static_cast<int>(app.crowd);
  if (ImGui::SliderInt("crowd", &crowd, 1, 256) && crowd != static_cast<int>(app.crowd)) {
    if (Status s = set_crowd(app, static_cast<size_t>(crowd), aspect); !s) ui.status = s.message();
  }
}

void stats_panel(const App& app, const UiState& ui) {
  const SceneCounts c = count(app.scene);
  ImGui::Text("joints %zu   meshes %zu   instances %zu", c.joints, c.meshes, app.crowd);
  ImGui::Text("vertices %zu   triangles %zu", c.vertices * app.crowd, c.triangles * app.crowd);
  const FrameTimings& t = ui.smoothed;
  ImGui::Text("frame %.2f ms (%.0f fps)", ui.frame_ms, ui.frame_ms > 0 ? 1000.0 / ui.frame_ms : 0.0);
  ImGui::Text("sample %.3f  blend %.3f  skin %.3f ms", t.sample_ms, t.blend_ms, t.skin_ms);
  ImGui::Text("draw %.3f ms (CPU)   GPU %.3f ms", t.draw_ms, t.gpu_ms);
}

void open_panel(App& app, UiState& ui, float aspect) {
  ImGui::InputText("##path", ui.open_path, sizeof ui.open_path);
  ImGui::SameLine();
  if (ImGui::Button("Open") && ui.open_path[0] != '\0') {
    const std::vector<std::string> paths{ui.open_path};
    const Status s = open_or_add(app, paths, aspect);
    ui.status = s ? std::string() : s.message();
  }
  ImGui::TextDisabled("a character replaces the scene; clip files add clips (or drop files here)");
}

}  // namespace

void record_frame(UiState& ui, const FrameTimings& f, double frame_ms) {
  smooth(ui.smoothed.sample_ms, f.sample_ms);
  smooth(ui.smoothed.blend_ms, f.blend_ms);
  smooth(ui.smoothed.skin_ms, f.skin_ms);
  smooth(ui.smoothed.draw_ms, f.draw_ms);
  if (f.gpu_ms > 0.0) smooth(ui.smoothed.gpu_ms, f.gpu_ms);
  smooth(ui.frame_ms, frame_ms);
}

void draw_panels(App& app, UiState& ui, float aspect) {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(360, 0), ImGuiCond_FirstUseEver);
  const std::string title = std::filesystem::path(app.scene.paths.front()).filename().string() + "###ossa";
  ImGui::Begin(title.c_str());
  if (ImGui::CollapsingHeader("Clips", ImGuiTreeNodeFlags_DefaultOpen)) clips_panel(app, ui);
  if (ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) view_panel(app, ui, aspect);
  if (ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen)) stats_panel(app, ui);
  if (ImGui::CollapsingHeader("Open")) open_panel(app, ui, aspect);
  if (!ui.status.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", ui.status.c_str());
  for (const std::string& m : app.messages) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s", m.c_str());
  ImGui::TextDisabled("drag: orbit  right-drag: pan  wheel: zoom");
  ImGui::TextDisabled("space: play/pause  B: bind pose  up/down: clip");
  ImGui::End();
}

}  // namespace ossa::view
