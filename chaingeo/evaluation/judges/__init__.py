"""Judges that pick one of several proposed actions: the built-in rules (:mod:`.selection`), a
vision-language model (:mod:`.model_judge`), and the registry by name (:mod:`.registry`)."""
