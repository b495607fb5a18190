# Frequency responses (docs/response.md): the mesh frequency swept up and down at each KHV design's point; RMS
# DTE and dynamic factor against w, jumps, impact classes and the linear natural frequencies.


rule frequency_response:
    input:
        kernels=KERNELS,
        design=design_file,
    output:
        cube=results("response", "{response}.nc"),
        figure=report(
            results("figures", "{response}.png"),
            caption="../report/frequency_response.rst",
            category=category,
            subcategory="Frequency response",
            labels={"design": "{design}"},
        ),
        caption=results("figures", "{response}.png.txt"),
    log:
        logs("response_{response}.log"),
    threads: 2
    params:
        spec=config_slice("responses"),
    script:
        "../scripts/frequency_response.py"


RESPONSE_TARGETS = runs_for(
    "responses",
    rules.frequency_response.output.cube,
    rules.frequency_response.output.figure,
)
