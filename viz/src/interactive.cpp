// erodem viewer — the interactive window: trackball camera, time slider, keys, picking
// (run_interactive in scene.hpp).
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "erodem/viz/scene.hpp"

namespace erodem::viz {

namespace {

/// The slider's title: "t = 1800 s".
std::string time_title(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "t = %g s", t);
  return buf;
}

/// The state the key and widget callbacks share.
struct Controller {
  Scene* scene = nullptr;
  vtkSliderWidget* slider = nullptr;
  vtkRenderWindowInteractor* interactor = nullptr;
  int play_timer = -1;  ///< the repeating timer while playing, -1 when paused
  bool top_view = false;

  void show_time(std::size_t index) {
    scene->set_time_index(index);
    if (slider) {
      auto* rep = static_cast<vtkSliderRepresentation2D*>(slider->GetRepresentation());
      rep->SetValue(static_cast<double>(scene->time_index()));
      rep->SetTitleText(time_title(scene->data().times()[scene->time_index()]).c_str());
    }
  }
  void step_time(int delta) {
    const long n = static_cast<long>(scene->data().times().size());
    const long k = (static_cast<long>(scene->time_index()) + delta % n + n) % n;
    show_time(static_cast<std::size_t>(k));
  }
  void step_field(int delta) {
    const auto& fields = scene->data().fields();
    const long n = static_cast<long>(fields.size());
    long k = 0;
    for (long i = 0; i < n; ++i)
      if (fields[static_cast<std::size_t>(i)].name == scene->field()) k = i;
    scene->set_field(fields[static_cast<std::size_t>(((k + delta) % n + n) % n)].name);
  }
  void toggle_play() {
    if (play_timer >= 0) {
      interactor->DestroyTimer(play_timer);
      play_timer = -1;
    } else {
      play_timer = interactor->CreateRepeatingTimer(500);
    }
  }
  void pick_at(int x, int y) {
    if (auto p = scene->pick(x, y)) std::printf("%s\n", pick_json(scene->data(), p->cell).c_str());
    std::fflush(stdout);
  }
};

/// Trackball camera plus the viewer's keys; a click (press and release without moving)
/// picks the cell under the cursor.
class ViewerStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static ViewerStyle* New();
  vtkTypeMacro(ViewerStyle, vtkInteractorStyleTrackballCamera) Controller* ctl = nullptr;

  void OnChar() override {
    auto* rwi = this->Interactor;
    const char key = rwi->GetKeyCode();
    Scene& s = *ctl->scene;
    if (key == 'n') {
      ctl->step_field(1);
    } else if (key == 'b') {
      ctl->step_field(-1);
    } else if (key >= '1' && key <= '9') {
      const std::size_t k = static_cast<std::size_t>(key - '1');
      if (k < s.data().fields().size()) s.set_field(s.data().fields()[k].name);
    } else if (key == ' ') {
      ctl->toggle_play();
    } else if (key == '+' || key == '=') {
      s.set_exaggeration(s.exaggeration() * 1.25);
    } else if (key == '-' || key == '_') {
      s.set_exaggeration(s.exaggeration() / 1.25);
    } else if (key == 'w') {
      s.set_water_visible(!s.water_visible());
    } else if (key == 't') {
      ctl->top_view = !ctl->top_view;
      s.reset_camera(ctl->top_view);
    } else if (key == 'r') {
      s.reset_camera(ctl->top_view);
    } else if (key == 'p') {
      ctl->pick_at(rwi->GetEventPosition()[0], rwi->GetEventPosition()[1]);
    } else if (key == '.') {  // the arrows come through OnKeyPress
      ctl->step_time(1);
    } else if (key == ',') {
      ctl->step_time(-1);
    } else if (key == 'q' || key == 'e') {
      vtkInteractorStyleTrackballCamera::OnChar();  // exit
      return;
    } else {
      return;  // VTK's other keys (wireframe, stereo, ...) are not used
    }
    rwi->Render();
  }
  void OnKeyPress() override {
    const std::string sym = this->Interactor->GetKeySym() ? this->Interactor->GetKeySym() : "";
    if (sym == "Right" || sym == "Left") {
      ctl->step_time(sym == "Right" ? 1 : -1);
      this->Interactor->Render();
      return;
    }
    vtkInteractorStyleTrackballCamera::OnKeyPress();
  }
  void OnLeftButtonDown() override {
    press_[0] = this->Interactor->GetEventPosition()[0];
    press_[1] = this->Interactor->GetEventPosition()[1];
    vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
  }
  void OnLeftButtonUp() override {
    vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
    const int* p = this->Interactor->GetEventPosition();
    if (std::abs(p[0] - press_[0]) + std::abs(p[1] - press_[1]) <= 2) {
      ctl->pick_at(p[0], p[1]);
      this->Interactor->Render();
    }
  }

 private:
  int press_[2] = {0, 0};
};
vtkStandardNewMacro(ViewerStyle);

void on_slider(vtkObject* caller, unsigned long, void* client, void*) {
  auto* ctl = static_cast<Controller*>(client);
  auto* widget = static_cast<vtkSliderWidget*>(caller);
  const double v = static_cast<vtkSliderRepresentation2D*>(widget->GetRepresentation())->GetValue();
  ctl->show_time(static_cast<std::size_t>(std::lround(std::max(0.0, v))));
}

/// Camera motion starts / ends: draw the coarse copy meanwhile.
void on_interaction(vtkObject*, unsigned long event, void* client, void*) {
  auto* ctl = static_cast<Controller*>(client);
  const bool start = event == vtkCommand::StartInteractionEvent;
  ctl->scene->set_interacting(start);
  if (!start && ctl->scene->has_interaction_lod()) ctl->interactor->Render();
}

void on_timer(vtkObject*, unsigned long, void* client, void* call_data) {
  auto* ctl = static_cast<Controller*>(client);
  if (ctl->play_timer < 0 || !call_data || *static_cast<int*>(call_data) != ctl->play_timer) return;
  ctl->step_time(1);
  ctl->interactor->Render();
}

}  // namespace

void run_interactive(Scene& scene, const std::vector<std::string>& keys,
                     const std::string& screenshot) {
  Controller ctl;
  ctl.scene = &scene;
  vtkNew<vtkRenderWindowInteractor> interactor;
  ctl.interactor = interactor;
  interactor->SetRenderWindow(scene.window());
  vtkNew<ViewerStyle> style;
  style->ctl = &ctl;
  interactor->SetInteractorStyle(style);

  vtkNew<vtkTextActor> help;
  help->SetInput(
      "n/b field  1-9 field #  space play  <-/-> time  +/- exaggeration  w water  t top view  "
      "click/p pick  r reset  q quit");
  help->GetTextProperty()->SetFontSize(13);
  help->GetTextProperty()->SetColor(0.85, 0.85, 0.85);
  help->GetTextProperty()->SetVerticalJustificationToTop();
  help->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  help->SetPosition(0.01, 0.945);
  scene.renderer()->AddActor2D(help);

  const auto& times = scene.data().times();
  vtkNew<vtkSliderRepresentation2D> rep;
  vtkNew<vtkSliderWidget> slider;
  if (times.size() > 1) {
    rep->SetMinimumValue(0.0);
    rep->SetMaximumValue(static_cast<double>(times.size() - 1));
    rep->SetValue(static_cast<double>(scene.time_index()));
    rep->ShowSliderLabelOff();
    rep->SetTitleText(time_title(times[scene.time_index()]).c_str());
    rep->GetPoint1Coordinate()->SetCoordinateSystemToNormalizedDisplay();
    rep->GetPoint1Coordinate()->SetValue(0.3, 0.07);
    rep->GetPoint2Coordinate()->SetCoordinateSystemToNormalizedDisplay();
    rep->GetPoint2Coordinate()->SetValue(0.8, 0.07);
    rep->SetSliderLength(0.02);
    rep->SetSliderWidth(0.03);
    rep->SetTubeWidth(0.008);
    rep->SetTitleHeight(0.025);
    slider->SetInteractor(interactor);
    slider->SetRepresentation(rep);
    slider->SetAnimationModeToJump();
    slider->EnabledOn();
    vtkNew<vtkCallbackCommand> cb;
    cb->SetCallback(on_slider);
    cb->SetClientData(&ctl);
    slider->AddObserver(vtkCommand::InteractionEvent, cb);
    ctl.slider = slider;
  }
  vtkNew<vtkCallbackCommand> motion;
  motion->SetCallback(on_interaction);
  motion->SetClientData(&ctl);
  style->AddObserver(vtkCommand::StartInteractionEvent, motion);
  style->AddObserver(vtkCommand::EndInteractionEvent, motion);
  vtkNew<vtkCallbackCommand> timer;
  timer->SetCallback(on_timer);
  timer->SetClientData(&ctl);
  interactor->AddObserver(vtkCommand::TimerEvent, timer);

  interactor->Initialize();
  scene.render();
  for (const auto& k : keys) {
    // A key as the window system delivers it: key press (arrows), then the character.
    const bool named = k.size() > 1;
    const char code = k == "space"   ? ' '
                      : k == "plus"  ? '+'
                      : k == "minus" ? '-'
                      : named        ? 0
                                     : k[0];
    const std::string sym = k == "space" ? "space" : named ? k : std::string(1, code);
    interactor->SetKeyEventInformation(0, 0, code, 1, sym.c_str());
    interactor->InvokeEvent(vtkCommand::KeyPressEvent);
    if (code) interactor->InvokeEvent(vtkCommand::CharEvent);
    interactor->InvokeEvent(vtkCommand::KeyReleaseEvent);
  }
  if (ctl.play_timer >= 0 && !screenshot.empty()) ctl.toggle_play();
  if (!screenshot.empty()) {
    scene.write_png(screenshot);
    return;
  }
  interactor->Start();
}

}  // namespace erodem::viz
