"""Many simulated robots at once: sweeps (:mod:`.spec`, :mod:`.plan`), the fleet itself (:mod:`.run`,
:mod:`.kernel`), the unit of work and where it runs (:mod:`.work`, :mod:`.backends`), pictures (:mod:`.plots`),
tuning (:mod:`.tune`) and the Gymnasium environments (:mod:`.env`)."""
