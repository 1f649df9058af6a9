"""The reproduction report: the JSON/HTML writer, the rows of stated numbers and their commands."""
