// The fuzz build compiles drivers/reproduce/reproduction_table.cpp without the paper values CMake embeds in the
// kushner binary: the paper_values target parses its own input, never an example's table by name.
namespace kushner::detail {
struct EmbeddedPaperValues {
  const char* example;
  const char* csv;
};
extern const EmbeddedPaperValues embedded_paper_values[] = {{"", ""}};
extern const int num_embedded_paper_values = 0;
}  // namespace kushner::detail
