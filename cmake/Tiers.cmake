# Every test is in exactly one tier, a ctest label (docs/testing.md):
#   unit         a module alone; milliseconds to a few seconds
#   integration  the program, the servers, the browser, the firmware under QEMU
#   acceptance   whole reproductions, `compare`, long seeded runs
# `make test-fast` runs `unit`; `make test` every tier in release; `make sanitize` `unit` and
# `integration` under ASan + UBSan. A tier's timeout bounds a hang, it is not a speed target
# (those live in bench/): unit 60 s, integration 300 s, acceptance 900 s (twice that under the
# sanitizers). tests/tiers checks that every registered test carries exactly one tier.
set(PIEZOSHIFT_TIERS unit integration acceptance)
set(PIEZOSHIFT_TIMEOUT_unit 60)
set(PIEZOSHIFT_TIMEOUT_integration 300)
set(PIEZOSHIFT_TIMEOUT_acceptance 900)
# Acceptance tests run once, in release: the sanitizer build (PIEZOSHIFT_SANITIZE) neither builds
# nor registers them. Under the sanitizers code runs 5 to 100 times slower (an Eigen fit of
# 0.4 s took 45 s), so there a hang is bounded at twice the tier's time.
if(PIEZOSHIFT_SANITIZE)
  set(PIEZOSHIFT_ACCEPTANCE_TESTS OFF)
  foreach(tier unit integration acceptance)
    math(EXPR PIEZOSHIFT_TIMEOUT_${tier} "2 * ${PIEZOSHIFT_TIMEOUT_${tier}}")
  endforeach()
else()
  set(PIEZOSHIFT_ACCEPTANCE_TESTS ON)
endif()

function(piezoshift_check_tier tier)
  if(NOT tier IN_LIST PIEZOSHIFT_TIERS)
    message(FATAL_ERROR "piezoshift tests: tier '${tier}' is not one of ${PIEZOSHIFT_TIERS}")
  endif()
endfunction()

# Puts tests registered with add_test() in a tier: its label and its timeout.
function(piezoshift_tier tier)
  piezoshift_check_tier(${tier})
  set_tests_properties(${ARGN} PROPERTIES LABELS ${tier} TIMEOUT ${PIEZOSHIFT_TIMEOUT_${tier}})
endfunction()
