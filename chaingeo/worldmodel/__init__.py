"""Video (world) models: what a model is given (:mod:`.prompt`), videos of plans, pose
trajectories and their exact check, and the judge that reads a video (:mod:`.judge_video`)."""
