# The firmware core's receive path under libFuzzer with ASan and UBSan
# (clang, from Debian). `make fuzz-short` (part of `make test`) runs a short
# while from the seeds and the kept findings; `make fuzz-long` (part of
# `make bench`) runs FUZZ_LONG_RUNS executions and prints what it found.
# Every finding is fixed and its input kept in tests/fuzz/regressions.

FUZZ_OUT := $(BUILD)/fuzz
FUZZ_CC ?= clang
FUZZ_FLAGS := -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
	-DQS_BOARD=0 -DQS_AXIS_COUNT=4 -DQS_QUEUE_CAPACITY=16 -DQS_TICK_HZ=50000UL -Ifirmware/core
FUZZ_SHORT_RUNS ?= 60000
FUZZ_LONG_RUNS ?= 10000000
FUZZ_REGRESSIONS := tests/fuzz/regressions

.PHONY: fuzz-short fuzz-long

$(FUZZ_OUT)/fuzz_core: tests/fuzz/fuzz_core.c $(sort $(wildcard firmware/core/*.c)) $(wildcard firmware/core/*.h)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_FLAGS) tests/fuzz/fuzz_core.c $(sort $(wildcard firmware/core/*.c)) -o $@

$(FUZZ_OUT)/seeds/.done: tests/fuzz/seeds.py protocol/vectors.json
	@rm -rf $(FUZZ_OUT)/seeds
	$(PYTHON) tests/fuzz/seeds.py $(FUZZ_OUT)/seeds
	@touch $@

# Every kept finding must run clean, then the seeds and a corpus of its own.
fuzz-short: $(FUZZ_OUT)/fuzz_core $(FUZZ_OUT)/seeds/.done
	@mkdir -p $(FUZZ_OUT)/corpus
	$(FUZZ_OUT)/fuzz_core -runs=0 $(FUZZ_REGRESSIONS) > $(FUZZ_OUT)/regressions.log 2>&1 || (cat $(FUZZ_OUT)/regressions.log; exit 1)
	@mkdir -p $(FUZZ_OUT)/findings
	$(FUZZ_OUT)/fuzz_core -runs=$(FUZZ_SHORT_RUNS) -max_len=512 -print_final_stats=1 -artifact_prefix=$(FUZZ_OUT)/findings/ \
	  $(FUZZ_OUT)/corpus $(FUZZ_OUT)/seeds > $(FUZZ_OUT)/short.log 2>&1 || (tail -40 $(FUZZ_OUT)/short.log; exit 1)
	@grep -E "stat::number_of_executed_units" $(FUZZ_OUT)/short.log | sed 's/^/fuzz (short): /'

fuzz-long: $(FUZZ_OUT)/fuzz_core $(FUZZ_OUT)/seeds/.done
	@mkdir -p $(FUZZ_OUT)/corpus $(FUZZ_OUT)/findings
	@$(FUZZ_OUT)/fuzz_core -runs=$(FUZZ_LONG_RUNS) -max_len=512 -print_final_stats=1 \
	  -artifact_prefix=$(FUZZ_OUT)/findings/ $(FUZZ_OUT)/corpus $(FUZZ_OUT)/seeds > $(FUZZ_OUT)/long.log 2>&1; \
	  status=$$?; \
	  grep -E "stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)" $(FUZZ_OUT)/long.log; \
	  echo "findings: $$(ls $(FUZZ_OUT)/findings | wc -l) (in $(FUZZ_OUT)/findings)"; exit $$status
