// placeholder until the scenario evaluation is written
