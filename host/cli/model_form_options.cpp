#include "model_form_options.hpp"

namespace pliant::cli {

void ModelFormOptions::add_to(CLI::App& app) {
  auto* alpha_option =
      app.add_option("--alpha", alpha_,
                     "msm_alpha: 'auto' (default) fits it with msm_beta when the recording determines it (BIC), "
                     "'fit' (also a bare --alpha) always, 'fixed=A' holds it at A in (0, 1] (the old default A = 1)")
          ->type_name("auto|fit|fixed=A")
          ->expected(0, 1);
  app.add_option("--msm-alpha", msm_alpha_, "Same as --alpha fixed=A")->type_name("A")->excludes(alpha_option);
  app.add_option("--steps-per-frame", steps_per_frame_,
                 "MSM steps per frame interval: 'auto' (default) chooses 1-4 with msm_alpha (BIC), or N in 1..64")
      ->type_name("auto|N")
      ->capture_default_str();
  app.add_option("--cluster-radius", cluster_radius_,
                 "MSM cluster radius over the median neighbour distance: 'auto' (default) chooses among 1.3-2.25 "
                 "with the rest (BIC), or F in [1, 4]")
      ->type_name("auto|F")
      ->capture_default_str();
}

ModelFormText ModelFormOptions::text(const CLI::App& app) const {
  ModelFormText text;
  if (app.count("--alpha") > 0) text.alpha = alpha_;
  if (app.count("--msm-alpha") > 0) text.msm_alpha = msm_alpha_;
  if (app.count("--steps-per-frame") > 0) text.steps_per_frame = steps_per_frame_;
  if (app.count("--cluster-radius") > 0) text.cluster_radius = cluster_radius_;
  return text;
}

}  // namespace pliant::cli
