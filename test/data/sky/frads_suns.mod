solar630
solar870
