# Labels the validation cases (`ctest -L validation`): the closed-form, benchmark and precision
# cases that the validation report (experiments/validation/run.py, docs/validation.md) runs with
# their full ladders. ctest includes this after the list gtest_discover_tests found
# (erodem_tests_TESTS).
foreach(t IN LISTS erodem_tests_TESTS)
  if(t MATCHES
     "^(Cpu|OpenCl)/(Analytical|Validation|Runoff|Waves|TerrainClasses|BoundarySediment|RasterParameters|RealDemLake|Snow|Infiltration|Stage|ShallowWater|Sediment|Sections|GriddedForcing)\\."
     OR t MATCHES
     "Physics\\.(SemiLagrangianLossIsMeasured|BedrockLevelIsNeverCut|LakeAtRestStaysAtRest|ClosedBoxConservesWaterAndMaterial)/"
     OR t MATCHES
     "Sources\\.(FixedLevelEdgeFillsADryChannelAtRittersSpeed|LargeInflowHydrographIntoADryBasin|LineInflowOnAPlainStaysSmoothAndSymmetric|HunterFloodFrontOnAFrictionalBed|HunterFloodFrontShallowWater)/"
     OR t MATCHES "^Precision\\.Float32")
    set_tests_properties("${t}" PROPERTIES LABELS validation)
  endif()
endforeach()
